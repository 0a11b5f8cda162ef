#include "src/scene/scene_loader.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "src/core/error.h"
#include "src/scene/json_fields.h"
#include "src/scene/mesh_loader.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string resolvePath(const std::string& scenePath, const std::string& file) {
  const fs::path p(file);
  if (p.is_absolute()) return p.lexically_normal().string();
  return (fs::path(scenePath).parent_path() / p).lexically_normal().string();
}

std::string indexed(const std::string& key, size_t i) {
  return key + "[" + std::to_string(i) + "]";
}

Transform parseTransform(JsonObject& parent, const std::string& key) {
  if (!parent.has(key)) return Transform();
  JsonObject t = parent.object(key);
  Transform xf;
  if (t.has("matrix")) {
    const std::vector<json> m = t.array("matrix", true);
    if (m.size() != 16) t.fail("matrix", "expected 16 numbers (row-major)");
    for (int i = 0; i < 16; ++i) {
      if (!m[static_cast<size_t>(i)].is_number()) t.fail("matrix", "expected 16 numbers");
      xf.m[i / 4][i % 4] = m[static_cast<size_t>(i)].get<float>();
    }
    if (xf.m[3][0] != 0 || xf.m[3][1] != 0 || xf.m[3][2] != 0 || xf.m[3][3] != 1)
      t.fail("matrix", "the last row must be [0, 0, 0, 1] (affine transforms only)");
  } else {
    Vec3 s(1.0f);
    if (t.has("scale")) {
      const json& sv = t.raw("scale");
      s = sv.is_number() ? Vec3(sv.get<float>()) : t.vec3("scale");
    }
    Transform r;
    if (t.has("rotate")) {
      JsonObject rot = t.object("rotate");
      const Vec3 axis = rot.vec3("axis");
      if (length(axis) == 0.0f) rot.fail("axis", "must not be zero");
      r = Transform::rotate(axis, rot.number("deg"));
      rot.finish();
    }
    const Vec3 tr = t.vec3("translate", Vec3(0.0f));
    xf = Transform::translate(tr) * r * Transform::scale(s);
  }
  t.finish();
  const float det = xf.determinant3();
  if (!std::isfinite(det) || std::abs(det) < 1e-12f)
    parent.fail(key, "the transform is singular (zero scale?)");
  return xf;
}

void parseCamera(JsonObject c, Camera& cam) {
  cam.position = c.vec3("position");
  cam.lookAt = c.vec3("look_at");
  cam.up = c.vec3("up", Vec3(0, 1, 0));
  cam.vfovDeg = c.number("vfov_deg", 45.0f);
  if (!(cam.vfovDeg > 0.0f && cam.vfovDeg < 180.0f)) c.fail("vfov_deg", "must be in (0, 180)");
  cam.width = c.integer("width", 1, 16384, 512);
  cam.height = c.integer("height", 1, 16384, 512);
  const Vec3 forward = cam.lookAt - cam.position;
  if (length(forward) == 0.0f) c.fail("look_at", "equals the camera position");
  if (length(cross(forward, cam.up)) < 1e-6f * length(forward) * length(cam.up))
    c.fail("up", "is parallel to the viewing direction");
  c.finish();
}

void parseRender(JsonObject r, RenderSettings& s) {
  s.mode = r.string("mode", s.mode);
  s.spp = r.integer("spp", 1, 1 << 20, s.spp);
  s.maxBounces = r.integer("max_bounces", 0, 1 << 16, s.maxBounces);
  s.seed = static_cast<uint64_t>(r.integer("seed", 0, std::numeric_limits<int>::max(), 1));
  s.areaLightSamples = r.integer("area_light_samples", 1, 1 << 16, s.areaLightSamples);
  s.mediumLightSamples = r.integer("medium_light_samples", 1, 1 << 16, s.mediumLightSamples);
  s.threads = r.integer("threads", 0, 1024, s.threads);
  r.finish();
}

void parseMaterials(JsonObject m, const json& value, Scene& scene) {
  for (auto it = value.begin(); it != value.end(); ++it) {
    JsonObject mat = m.object(it.key());
    Material material;
    material.name = it.key();
    material.albedo = mat.rgb("albedo", 0.0f, 1.0f, RGB(0.8f));
    material.emission = mat.rgb("emission", 0.0f, 1e9f, RGB(0.0f));
    mat.finish();
    scene.materials.push_back(material);
  }
}

uint32_t findMaterial(JsonObject& o, const Scene& scene) {
  const std::string name = o.string("material");
  for (size_t i = 0; i < scene.materials.size(); ++i)
    if (scene.materials[i].name == name) return static_cast<uint32_t>(i);
  o.fail("material", "unknown material '" + name + "'");
}

void addQuad(Scene& scene, const Vec3 c[4], uint32_t material) {
  addTriangle(scene.mesh, c[0], c[1], c[2], material);
  addTriangle(scene.mesh, c[0], c[2], c[3], material);
}

void addBox(Scene& scene, const Vec3& lo, const Vec3& hi, const Transform& xf, uint32_t material) {
  auto corner = [&](int i) {
    return xf.point(Vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z));
  };
  // Faces as corner indices, counter-clockwise seen from outside.
  static constexpr int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                      {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    const Vec3 q[4] = {corner(f[0]), corner(f[1]), corner(f[2]), corner(f[3])};
    addQuad(scene, q, material);
  }
}

void parseShape(JsonObject s, Scene& scene) {
  const std::string type = s.string("type");
  const Transform xf = parseTransform(s, "transform");
  if (type == "obj") {
    const std::string file = resolvePath(scene.path, s.string("file"));
    const std::string material = s.string("material", std::string());
    scene.inputFiles.push_back(file);
    loadObj(file, s.fieldPath("file"), xf, material, scene);
  } else if (type == "ply") {
    const std::string file = resolvePath(scene.path, s.string("file"));
    const uint32_t material = findMaterial(s, scene);
    scene.inputFiles.push_back(file);
    loadPly(file, s.fieldPath("file"), xf, material, scene);
  } else if (type == "quad") {
    const std::vector<json> corners = s.array("corners", true);
    if (corners.size() != 4) s.fail("corners", "expected 4 corners");
    Vec3 c[4];
    for (size_t i = 0; i < 4; ++i) {
      json wrapper = {{"p", corners[i]}};
      JsonObject w(wrapper, s.file(), s.fieldPath(indexed("corners", i)));
      c[i] = xf.point(w.vec3("p"));
    }
    const size_t before = scene.mesh.triangleCount();
    addQuad(scene, c, findMaterial(s, scene));
    if (scene.mesh.triangleCount() == before) s.fail("corners", "the quad is degenerate");
  } else if (type == "box") {
    const Vec3 lo = s.vec3("min"), hi = s.vec3("max");
    if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z))
      s.fail("max", "must exceed min on every axis");
    addBox(scene, lo, hi, xf, findMaterial(s, scene));
  } else {
    s.fail("type", "unknown shape type '" + type + "' (obj, ply, quad, box)");
  }
  s.finish();
}

Vec3 unitDirection(JsonObject& o, const std::string& key) {
  const Vec3 d = o.vec3(key);
  if (length(d) == 0.0f) o.fail(key, "must not be zero");
  return normalize(d);
}

void parseLight(JsonObject l, Scene& scene) {
  Light light;
  const std::string type = l.string("type");
  if (type == "directional") {
    light.type = LightType::Directional;
    light.direction = unitDirection(l, "direction");
    light.intensity = l.rgb("irradiance", 0.0f, 1e9f);
  } else if (type == "point") {
    light.type = LightType::Point;
    light.position = l.vec3("position");
    light.intensity = l.rgb("intensity", 0.0f, 1e12f);
  } else if (type == "spot") {
    light.type = LightType::Spot;
    light.position = l.vec3("position");
    light.direction = unitDirection(l, "direction");
    light.intensity = l.rgb("intensity", 0.0f, 1e12f);
    light.coneDeg = l.number("cone_deg", 0.01f, 90.0f, 30.0f);
    light.falloffDeg = l.number("falloff_deg", 0.0f, light.coneDeg, std::min(5.0f, light.coneDeg));
  } else if (type == "environment") {
    light.type = LightType::Environment;
    light.intensity = l.rgb("radiance", 0.0f, 1e9f);
  } else {
    l.fail("type", "unknown light type '" + type + "' (directional, point, spot, environment)");
  }
  l.finish();
  scene.lights.push_back(light);
}

void parseMedium(JsonObject m, size_t index, Scene& scene) {
  MediumDesc d;
  d.field = indexed("media", index);
  const std::string type = m.string("type");
  d.g = m.number("g", -0.999f, 0.999f, 0.0f);
  d.phase = m.string("phase", d.g == 0.0f ? "isotropic" : "hg");
  if (d.phase != "isotropic" && d.phase != "hg" && d.phase != "schlick")
    m.fail("phase", "unknown phase function '" + d.phase + "' (isotropic, hg, schlick)");
  if (type == "vdb") {
    d.type = MediumType::Vdb;
    d.file = resolvePath(scene.path, m.string("file"));
    d.grid = m.string("grid", "density");
    if (d.grid.empty()) m.fail("grid", "must not be empty");
    d.emissionGrid = m.string("emission_grid", std::string());
    d.densityScale = m.number("density_scale", 0.0f, 1e9f, 1.0f);
    d.albedo = m.rgb("albedo", 0.0f, 1.0f, RGB(0.8f));
    d.emission = m.rgb("emission", 0.0f, 1e9f, RGB(0.0f));
    d.transform = parseTransform(m, "transform");
    scene.inputFiles.push_back(d.file);
  } else if (type == "homogeneous" || type == "procedural") {
    d.type = type == "homogeneous" ? MediumType::Homogeneous : MediumType::Procedural;
    d.boxMin = m.vec3("min");
    d.boxMax = m.vec3("max");
    if (!(d.boxMin.x < d.boxMax.x && d.boxMin.y < d.boxMax.y && d.boxMin.z < d.boxMax.z))
      m.fail("max", "must exceed min on every axis");
    d.sigmaA = m.rgb("sigma_a", 0.0f, 1e9f, RGB(0.0f));
    d.sigmaS = m.rgb("sigma_s", 0.0f, 1e9f, RGB(0.0f));
    d.emission = m.rgb("emission", 0.0f, 1e9f, RGB(0.0f));
    if (d.type == MediumType::Procedural) {
      const std::string kind = m.string("kind");
      if (kind == "constant") {
        d.procedural = ProceduralKind::Constant;
      } else if (kind == "linear_ramp") {
        d.procedural = ProceduralKind::LinearRamp;
        d.gradient = m.vec3("gradient");
      } else if (kind == "gaussian_blob") {
        d.procedural = ProceduralKind::GaussianBlob;
        d.center = m.vec3("center");
        d.radius = m.number("radius", 1e-6f, 1e9f, std::nullopt);
      } else if (kind == "noise") {
        d.procedural = ProceduralKind::Noise;
        d.frequency = m.number("frequency", 1e-6f, 1e6f, std::nullopt);
      } else {
        m.fail("kind", "unknown procedural kind '" + kind +
                           "' (constant, linear_ramp, gaussian_blob, noise)");
      }
    }
  } else {
    m.fail("type", "unknown medium type '" + type + "' (vdb, homogeneous, procedural)");
  }
  m.finish();
  scene.media.push_back(d);
}

void parseVolumeIntegrator(JsonObject v, VolumeIntegratorSettings& s) {
  s.solver = v.string("solver", s.solver);
  s.step = v.number("step", 1e-6f, 1e9f, s.step);
  s.tolerance = v.number("tolerance", 1e-12f, 1.0f, s.tolerance);
  s.minStep = v.number("min_step", 1e-9f, 1e9f, s.minStep);
  s.maxStep = v.number("max_step", 1e-9f, 1e9f, s.maxStep);
  if (s.minStep > s.maxStep) v.fail("min_step", "exceeds max_step");
  s.interpolation = v.string("interpolation", s.interpolation);
  if (s.interpolation != "nearest" && s.interpolation != "trilinear" &&
      s.interpolation != "tricubic")
    v.fail("interpolation",
           "unknown interpolation '" + s.interpolation + "' (nearest, trilinear, tricubic)");
  s.sampling = v.string("sampling", s.sampling);
  if (s.sampling != "none" && s.sampling != "distance" && s.sampling != "equiangular")
    v.fail("sampling", "unknown sampling '" + s.sampling + "' (none, distance, equiangular)");
  s.maxEvaluations = static_cast<uint32_t>(v.integer("max_evaluations", 1, 1 << 30, 100000));
  const std::string majorant = v.string("majorant", "grid");
  if (majorant != "grid" && majorant != "global")
    v.fail("majorant", "unknown majorant '" + majorant + "' (grid, global)");
  s.majorantGrid = majorant == "grid";
  v.finish();
}

void parsePointCloud(JsonObject p, PointCloudSettings& s) {
  s.surfelSpacing = p.number("surfel_spacing", 0.0f, 1e9f, s.surfelSpacing);
  s.lvoxelSpacing = p.number("lvoxel_spacing", 0.0f, 1e9f, s.lvoxelSpacing);
  s.lvoxelSamples = p.integer("lvoxel_samples", 1, 8, s.lvoxelSamples);
  s.lvoxelGatherSamples = p.integer("lvoxel_gather_samples", 1, 1 << 16, s.lvoxelGatherSamples);
  s.gatherSpacing = p.integer("gather_spacing", 1, 64, s.gatherSpacing);
  s.gatherFilter = p.number("gather_filter", 1.0f, 16.0f, s.gatherFilter);
  s.bounces = p.integer("bounces", 0, 1024, s.bounces);
  s.burialReach = p.number("burial_reach", 0.0f, 1e3f, s.burialReach);
  s.gatherVisibility = p.string("gather_visibility", s.gatherVisibility);
  if (s.gatherVisibility != "cloud" && s.gatherVisibility != "rays")
    p.fail("gather_visibility", "unknown visibility '" + s.gatherVisibility + "' (cloud, rays)");
  s.surfelGatherSamples = p.integer("surfel_gather_samples", 1, 1 << 16, s.surfelGatherSamples);
  s.targetSurfels = p.integer("target_surfels", 1, 1 << 28, s.targetSurfels);
  s.surfelSampler = p.string("surfel_sampler", s.surfelSampler);
  if (s.surfelSampler != "uniform" && s.surfelSampler != "camera")
    p.fail("surfel_sampler", "unknown sampler '" + s.surfelSampler + "' (uniform, camera)");
  s.gatherSamples = p.integer("gather_samples", 1, 1 << 16, s.gatherSamples);
  s.lvoxelClusterSolidAngle =
      p.number("lvoxel_cluster_solid_angle", 0.0f, 4.0f * kPi, s.lvoxelClusterSolidAngle);
  s.clusterSolidAngle = p.number("cluster_solid_angle", 0.0f, 4.0f * kPi, s.clusterSolidAngle);
  p.finish();
}

json parseJson(const std::string& text, const std::string& path) {
  try {
    return json::parse(text);
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

}  // namespace

Scene parseScene(const std::string& text, const std::string& path) {
  const json root = parseJson(text, path);
  Scene scene;
  scene.path = path;
  scene.inputFiles.push_back(path);
  JsonObject top(root, path, "");
  parseCamera(top.object("camera"), scene.camera);
  if (top.has("render")) parseRender(top.object("render"), scene.render);
  if (top.has("materials")) parseMaterials(top.object("materials"), root["materials"], scene);
  const std::vector<json> shapes = top.array("shapes");
  for (size_t i = 0; i < shapes.size(); ++i)
    parseShape(JsonObject(shapes[i], path, indexed("shapes", i)), scene);
  const std::vector<json> lights = top.array("lights");
  for (size_t i = 0; i < lights.size(); ++i)
    parseLight(JsonObject(lights[i], path, indexed("lights", i)), scene);
  const std::vector<json> media = top.array("media");
  for (size_t i = 0; i < media.size(); ++i)
    parseMedium(JsonObject(media[i], path, indexed("media", i)), i, scene);
  if (top.has("volume_integrator"))
    parseVolumeIntegrator(top.object("volume_integrator"), scene.volume);
  if (top.has("pointcloud")) parsePointCloud(top.object("pointcloud"), scene.pointcloud);
  top.finish();
  return scene;
}

Scene loadScene(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", std::string("cannot open scene: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  return parseScene(text.str(), fs::absolute(path).lexically_normal().string());
}

}  // namespace lvox
