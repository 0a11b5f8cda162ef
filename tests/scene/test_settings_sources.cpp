// Settings are parsed by the library that owns them into typed values, flags pass the same
// checks as the fields they set and are named in errors, and every setting is checked
// before any mesh is read.
#include <gtest/gtest.h>

#include <map>

#include "src/core/error.h"
#include "src/scene/scene_loader.h"
#include "test_util.h"

namespace lvox {
namespace {

// A scene whose only shape is an OBJ that does not exist: parsing reaches the mesh only
// when every setting passed.
const char* kMissingMesh = R"({
  "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "width": 8, "height": 8},
  "render": {"mode": "MODE"},
  "volume_integrator": {"solver": "SOLVER", "sampling": "SAMPLING", "interpolation": "INTERP"},
  "pointcloud": {"gather_visibility": "VIS"},
  "shapes": [{"type": "obj", "file": "no-such-mesh.obj"}],
  "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2}]
})";

std::string scene(const std::string& mode, const std::string& solver, const std::string& sampling,
                  const std::string& interp, const std::string& vis) {
  std::string s = kMissingMesh;
  for (const auto& [key, value] : {std::pair<std::string, std::string>{"MODE", mode},
                                   {"SOLVER", solver},
                                   {"SAMPLING", sampling},
                                   {"INTERP", interp},
                                   {"VIS", vis}})
    s.replace(s.find(key), key.size(), value);
  return s;
}

std::string errorOf(const std::string& text, const std::vector<SettingOverride>& flags = {}) {
  try {
    parseScene(text, "/tmp/settings.json", flags);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const std::string kValid = scene("pcb", "auto", "none", "trilinear", "cloud");

TEST(SettingsSources, ValidSettingsReachTheMeshLoader) {
  EXPECT_NE(errorOf(kValid).find("no-such-mesh.obj"), std::string::npos) << errorOf(kValid);
}

TEST(SettingsSources, EveryBadNameInTheFileIsRefusedBeforeTheMesh) {
  const std::pair<std::string, std::string> cases[] = {
      {scene("pbc", "auto", "none", "trilinear", "cloud"), "render.mode: unknown mode 'pbc'"},
      {scene("pcb", "rk5", "none", "trilinear", "cloud"),
       "volume_integrator.solver: unknown solver 'rk5'"},
      {scene("pcb", "auto", "importance", "trilinear", "cloud"),
       "volume_integrator.sampling: unknown sampling 'importance'"},
      {scene("pcb", "auto", "none", "cubic", "cloud"),
       "volume_integrator.interpolation: unknown interpolation 'cubic'"},
      {scene("pcb", "auto", "none", "trilinear", "exact"),
       "pointcloud.gather_visibility: unknown visibility 'exact'"}};
  for (const auto& [text, expected] : cases) {
    const std::string msg = errorOf(text);
    EXPECT_EQ(msg.rfind("/tmp/settings.json: ", 0), 0u) << msg;
    EXPECT_NE(msg.find(expected), std::string::npos) << msg;
  }
}

TEST(SettingsSources, FlagsAreCheckedLikeTheirFieldsAndNamedInErrors) {
  const std::pair<SettingOverride, std::string> cases[] = {
      {{"--mode", "render", "mode", "nope"}, "--mode: unknown mode 'nope'"},
      {{"--solver", "volume_integrator", "solver", "rk5"}, "--solver: unknown solver 'rk5'"},
      {{"--step", "volume_integrator", "step", 1e-9}, "--step: value 1e-09 is outside"},
      {{"--tol", "volume_integrator", "tolerance", 5.0}, "--tol: value 5 is outside"},
      {{"--seed", "render", "seed", -1}, "--seed: value -1 is outside"},
      {{"--spp", "render", "spp", 0}, "--spp: value 0 is outside"},
      {{"--adaptive-spp", "render", "adaptive_spp", 3},
       "--adaptive-spp: must be 0 (none) or more than render.spp (4)"},
      {{"--width", "camera", "width", 100000}, "--width: value 100000 is outside"}};
  for (const auto& [flag, expected] : cases) {
    const std::string msg = errorOf(kValid, {flag});
    EXPECT_EQ(msg.rfind(expected, 0), 0u) << msg;
  }
}

TEST(SettingsSources, FlagsOverrideTheFileAsTypedValues) {
  std::string text = kValid;
  text.replace(
      text.find("\"shapes\": [{\"type\": \"obj\", \"file\": \"no-such-mesh.obj\"}]"),
      std::string("\"shapes\": [{\"type\": \"obj\", \"file\": \"no-such-mesh.obj\"}]").size(),
      "\"shapes\": []");
  const Scene s = parseScene(text, "/tmp/settings.json",
                             {{"--mode", "render", "mode", "mc"},
                              {"--solver", "volume_integrator", "solver", "dopri5"},
                              {"--width", "camera", "width", 17}});
  EXPECT_EQ(s.render.mode, Mode::kMc);
  ASSERT_TRUE(s.volume.solver.has_value());
  EXPECT_EQ(*s.volume.solver, rte::Method::kDopri5);
  EXPECT_EQ(s.world.camera.width, 17);
  EXPECT_EQ(s.pointcloud.gatherVisibility, GatherVisibility::kCloud);  // from the file
  EXPECT_EQ(s.volume.interpolation, Interpolation::Trilinear);
  const Scene automatic = parseScene(text, "/tmp/settings.json");
  EXPECT_FALSE(automatic.volume.solver.has_value()) << "auto is the empty solver";
}

// Steps: absent means relative to the media (step_scale times their own step); a given
// step is in scene units, and step_scale cannot scale it.
TEST(SettingsSources, AStepIsRelativeUnlessTheSceneGivesOne) {
  const std::string base = R"({"camera": {"position": [0,0,1], "look_at": [0,0,0]},
    "volume_integrator": {INTEGRATOR}})";
  auto with = [&](const std::string& integrator) {
    std::string text = base;
    text.replace(text.find("INTEGRATOR"), 10, integrator);
    return text;
  };
  const Scene relative = parseScene(with(R"("step_scale": 0.5)"), "/tmp/settings.json");
  EXPECT_FALSE(relative.volume.step.has_value());
  EXPECT_FALSE(relative.volume.minStep.has_value());
  EXPECT_FALSE(relative.volume.maxStep.has_value());
  EXPECT_EQ(relative.volume.stepScale, 0.5f);
  const Scene absolute = parseScene(with(R"("step": 0.2, "max_step": 3)"), "/tmp/settings.json",
                                    {{"--step", "volume_integrator", "step", 0.05}});
  ASSERT_TRUE(absolute.volume.step.has_value());
  EXPECT_EQ(*absolute.volume.step, 0.05f);  // the flag
  EXPECT_EQ(absolute.volume.maxStep, 3.0f);
  EXPECT_FALSE(absolute.volume.minStep.has_value());
  // What a render's header records: "relative" where the scene gave no length.
  std::map<std::string, std::string> described;
  const SettingList list = describe(relative.volume);
  for (const auto& [field, value] : list.items()) described[field] = value;
  EXPECT_EQ(described["volume_integrator.step"], "relative");
  EXPECT_EQ(described["volume_integrator.step_scale"], "0.5");
  EXPECT_EQ(described["volume_integrator.max_step"], "relative");
  const std::pair<std::string, std::string> refused[] = {
      {R"("step": 0.1, "step_scale": 2)", "volume_integrator.step_scale: scales the relative step"},
      {R"("step_scale": 0)", "volume_integrator.step_scale: value 0 is outside"},
      {R"("min_step": 2, "max_step": 1)", "volume_integrator.min_step: exceeds max_step"}};
  for (const auto& [integrator, expected] : refused) {
    const std::string msg = errorOf(with(integrator));
    EXPECT_NE(msg.find(expected), std::string::npos) << msg;
  }
}

TEST(SettingsSources, AFlagForASectionThatIsNotAnObjectIsAnError) {
  const std::string msg =
      errorOf(R"({"camera": {"position": [0,0,1], "look_at": [0,0,0]}, "render": 3})",
              {{"--spp", "render", "spp", 2}});
  EXPECT_NE(msg.find("render"), std::string::npos) << msg;
  EXPECT_NE(msg.find("--spp"), std::string::npos) << msg;
}

}  // namespace
}  // namespace lvox
