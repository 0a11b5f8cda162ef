#include "src/scene/scene_loader.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "src/core/error.h"
#include "src/core/json_fields.h"
#include "src/world/world_loader.h"
#include "volume/media/media_set.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string indexed(const std::string& key, size_t i) {
  return key + "[" + std::to_string(i) + "]";
}

// Object keys seen so far, per nesting level, to refuse a key given twice (JSON parsers
// silently keep the last one). Arrays push an empty level.
class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(const std::string& path) : path_(path) {}
  bool operator()(int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        levels_.push_back({{}, ""});
        break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        levels_.pop_back();
        break;
      case json::parse_event_t::key: {
        Level& level = levels_.back();
        level.current = parsed.get<std::string>();
        if (!level.keys.insert(level.current).second)
          throw InputError(path_, fieldPath(), "given twice in one object");
        break;
      }
      case json::parse_event_t::value:
        break;
    }
    return true;
  }

 private:
  struct Level {
    std::set<std::string> keys;
    std::string current;
  };
  std::string fieldPath() const {
    std::string p;
    for (const Level& l : levels_)
      if (!l.current.empty()) p += (p.empty() ? "" : ".") + l.current;
    return p;
  }
  std::string path_;
  std::vector<Level> levels_;
};

json parseJson(const std::string& text, const std::string& path) {
  try {
    return json::parse(text, DuplicateKeyCheck(path));
  } catch (const json::parse_error& e) {
    // Turn the byte offset into line and column.
    size_t line = 1, col = 1;
    for (size_t i = 0; i + 1 < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    std::string what = e.what();
    const size_t colon = what.find("syntax error");
    if (colon != std::string::npos) what = what.substr(colon);
    throw InputError(path, "line " + std::to_string(line) + ", column " + std::to_string(col),
                     "malformed JSON: " + what);
  } catch (const json::exception& e) {
    throw InputError(path, "", std::string("malformed JSON: ") + e.what());
  }
}

// Writes each flag's value into its section (created when the file has none) and records
// the flag as the value's source.
std::shared_ptr<FlagSources> applyOverrides(json& root, const std::string& path,
                                            const std::vector<SettingOverride>& overrides) {
  auto sources = std::make_shared<FlagSources>();
  if (!root.is_object()) return sources;  // JsonObject reports it
  for (const SettingOverride& o : overrides) {
    if (!root.contains(o.section)) root[o.section] = json::object();
    json& section = root[o.section];
    if (!section.is_object())
      throw InputError(path, o.section, "must be an object (to take " + o.flag + ")");
    section[o.key] = o.value;
    (*sources)[o.section + "." + o.key] = o.flag;
  }
  return sources;
}

// The sections that hold settings, media and lights, in full: nothing here loads a file.
void parseSettings(JsonObject& top, Scene& scene) {
  // Without a "camera" section the scene takes a glTF shape's camera (parseScene).
  if (top.has("camera")) scene.world.camera = parseCamera(top.object("camera"));
  if (top.has("render")) scene.render = parseRenderSettings(top.object("render"));
  if (top.has("volume_integrator"))
    scene.volume = parseVolumeSettings(top.object("volume_integrator"));
  if (top.has("pointcloud")) scene.pointcloud = parsePointCloudSettings(top.object("pointcloud"));
  const std::vector<json> media = top.array("media");
  if (media.size() > kMaxMedia)
    top.fail("media", "at most " + std::to_string(kMaxMedia) + " media are supported");
  for (size_t i = 0; i < media.size(); ++i) {
    scene.media.push_back(parseMedium(JsonObject(media[i], top.file(), indexed("media", i))));
    if (scene.media.back().type == MediumType::Vdb)
      scene.inputFiles.push_back(scene.media.back().file);
  }
  const std::vector<json> lights = top.array("lights");
  for (size_t i = 0; i < lights.size(); ++i)
    scene.world.lights.push_back(
        parseLight(JsonObject(lights[i], top.file(), indexed("lights", i))));
}

}  // namespace

Scene parseScene(const std::string& text, const std::string& path,
                 const std::vector<SettingOverride>& overrides) {
  json root = parseJson(text, path);
  const std::shared_ptr<FlagSources> sources = applyOverrides(root, path, overrides);
  Scene scene;
  scene.path = path;
  scene.inputFiles.push_back(path);
  JsonObject top(root, path, "", sources);
  parseSettings(top, scene);
  if (top.has("materials")) parseMaterials(top.object("materials"), scene.world);
  const std::vector<json> shapes = top.array("shapes");
  top.finish();  // a misspelled section fails before any mesh is read
  std::optional<Camera> fileCamera;
  for (size_t i = 0; i < shapes.size(); ++i)
    parseShape(JsonObject(shapes[i], path, indexed("shapes", i)), scene.world, scene.inputFiles,
               fileCamera);
  if (!root.contains("camera")) {
    if (!fileCamera) throw InputError(path, "camera", "missing (and no glTF shape has a camera)");
    scene.world.camera = *fileCamera;
  }
  for (size_t i = 0; i < scene.world.lights.size(); ++i) {
    const Light& light = scene.world.lights[i];
    if (light.file.empty()) continue;
    const std::string field = indexed("lights", i) + ".file";
    if (scene.world.environmentMap) throw InputError(path, field, "only one environment map");
    scene.world.environmentMap =
        std::make_shared<EnvironmentMap>(light.file, light.intensity, path, field);
    scene.inputFiles.push_back(light.file);
  }
  // Textures are inputs too: no output may replace one, and the scene hash covers them.
  for (const TextureFile& t : scene.world.textures) scene.inputFiles.push_back(t.path);
  return scene;
}

Scene loadScene(const std::string& path, const std::vector<SettingOverride>& overrides) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", std::string("cannot open scene: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  return parseScene(text.str(), fs::absolute(path).lexically_normal().string(), overrides);
}

}  // namespace lvox
