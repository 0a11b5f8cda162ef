#include "src/world/world_loader.h"

#include <optional>

#include "src/core/names.h"
#include "src/world/gltf_loader.h"
#include "src/world/mesh_loader.h"
#include "src/world/surface_textures.h"

namespace lvox {
namespace {

enum class ShapeType { Obj, Ply, Gltf, Quad, Box };
constexpr Named<ShapeType> kShapeTypes[] = {{ShapeType::Obj, "obj"},
                                            {ShapeType::Ply, "ply"},
                                            {ShapeType::Gltf, "gltf"},
                                            {ShapeType::Quad, "quad"},
                                            {ShapeType::Box, "box"}};
ShapeType parseShapeType(std::string_view name, const std::string& file, const std::string& field) {
  return parseNamed(name, kShapeTypes, "shape type", file, field);
}

constexpr Named<LightType> kLightTypes[] = {{LightType::Directional, "directional"},
                                            {LightType::Point, "point"},
                                            {LightType::Spot, "spot"},
                                            {LightType::Environment, "environment"}};
LightType parseLightType(std::string_view name, const std::string& file, const std::string& field) {
  return parseNamed(name, kLightTypes, "light type", file, field);
}

std::string indexed(const std::string& key, size_t i) {
  return key + "[" + std::to_string(i) + "]";
}

uint32_t findMaterial(JsonObject& o, const World& world) {
  const std::string name = o.string("material");
  for (size_t i = 0; i < world.materials.size(); ++i)
    if (world.materials[i].name == name) return static_cast<uint32_t>(i);
  o.fail("material", "unknown material '" + name + "'");
}

void addQuad(World& world, const Vec3* c, uint32_t material) {
  addTriangle(world.mesh, c[0], c[1], c[2], material);
  addTriangle(world.mesh, c[0], c[2], c[3], material);
}

void addBox(World& world, const Vec3& lo, const Vec3& hi, const Transform& xf, uint32_t material) {
  auto corner = [&](int i) {
    return xf.point(Vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z));
  };
  // Faces as corner indices, counter-clockwise seen from outside.
  static constexpr int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                      {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    const Vec3 q[4] = {corner(f[0]), corner(f[1]), corner(f[2]), corner(f[3])};
    addQuad(world, q, material);
  }
}

Vec3 unitDirection(JsonObject& o, const std::string& key) {
  const Vec3 d = o.vec3(key);
  if (length(d) == 0.0f) o.fail(key, "must not be zero");
  return normalize(d);
}

}  // namespace

Camera parseCamera(JsonObject c) {
  Camera cam;
  cam.position = c.vec3("position");
  cam.lookAt = c.vec3("look_at");
  cam.up = c.vec3("up", Vec3(0, 1, 0));
  cam.vfovDeg = c.number("vfov_deg", 45.0f);
  if (!(cam.vfovDeg > 0.0f && cam.vfovDeg < 180.0f)) c.fail("vfov_deg", "must be in (0, 180)");
  cam.width = c.integer("width", 1, 16384, 512);
  cam.height = c.integer("height", 1, 16384, 512);
  if (length(cam.up) == 0.0f) c.fail("up", "must not be zero");
  const Vec3 forward = cam.lookAt - cam.position;
  if (length(forward) == 0.0f) c.fail("look_at", "equals the camera position");
  if (length(cross(forward, cam.up)) < 1e-6f * length(forward) * length(cam.up))
    c.fail("up", "is parallel to the viewing direction");
  c.finish();
  return cam;
}

void parseMaterials(JsonObject m, World& world) {
  for (const std::string& name : m.keys()) {
    JsonObject mat = m.object(name);
    Material material;
    material.name = name;
    material.albedo = mat.rgb("albedo", 0.0f, 1.0f, RGB(0.8f));
    material.emission = mat.rgb("emission", 0.0f, 1e9f, RGB(0.0f));
    if (mat.has("albedo_texture")) {
      // The texture times "albedo" (1 unless given), on the shape's texture coordinates.
      const TextureFile file{mat.filePath("albedo_texture"), mat.file(),
                             mat.fieldPath("albedo_texture")};
      requireReadableTexture(file);
      material.albedoMap = world.textureIndex(file);
      material.albedo = mat.rgb("albedo", 0.0f, 1.0f, RGB(1.0f));
    }
    mat.finish();
    world.materials.push_back(material);
  }
}

std::vector<Vec3> quadCorners(JsonObject& s, const Transform& xf) {
  const std::vector<nlohmann::json> corners = s.array("corners", true);
  if (corners.size() != 4) s.fail("corners", "expected 4 corners");
  std::vector<Vec3> c(4);
  for (size_t i = 0; i < 4; ++i) {
    const nlohmann::json wrapper = {{"p", corners[i]}};
    JsonObject w(wrapper, s.file(), s.fieldPath(indexed("corners", i)));
    c[i] = xf.point(w.vec3("p"));
  }
  return c;
}

void parseShape(JsonObject s, World& world, std::vector<std::string>& inputFiles,
                std::optional<Camera>& fileCamera) {
  const ShapeType type = s.choice("type", std::nullopt, parseShapeType);
  const Transform xf = parseTransform(s, "transform");
  switch (type) {
    case ShapeType::Obj: {
      const std::string file = s.filePath("file");
      std::optional<uint32_t> material;
      if (s.has("material")) material = findMaterial(s, world);
      inputFiles.push_back(file);
      loadObj(file, s.fieldPath("file"), xf, material, world);
      for (const std::string& mtl : objMaterialLibraries(file)) inputFiles.push_back(mtl);
      break;
    }
    case ShapeType::Ply: {
      const std::string file = s.filePath("file");
      const uint32_t material = findMaterial(s, world);
      inputFiles.push_back(file);
      loadPly(file, s.fieldPath("file"), xf, material, world);
      break;
    }
    case ShapeType::Gltf: {
      const std::string file = s.filePath("file");
      inputFiles.push_back(file);
      loadGltf(file, s.fieldPath("file"), xf, world, fileCamera);
      break;
    }
    case ShapeType::Quad: {
      const std::vector<Vec3> c = quadCorners(s, xf);
      const size_t before = world.mesh.triangleCount();
      addQuad(world, c.data(), findMaterial(s, world));
      if (world.mesh.triangleCount() == before) s.fail("corners", "the quad is degenerate");
      break;
    }
    case ShapeType::Box: {
      const Vec3 lo = s.vec3("min"), hi = s.vec3("max");
      if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z))
        s.fail("max", "must exceed min on every axis");
      addBox(world, lo, hi, xf, findMaterial(s, world));
      break;
    }
  }
  s.finish();
}

Light parseLight(JsonObject l) {
  Light light;
  light.type = l.choice("type", std::nullopt, parseLightType);
  switch (light.type) {
    case LightType::Directional:
      light.direction = unitDirection(l, "direction");
      light.intensity = l.rgb("irradiance", 0.0f, 1e9f);
      break;
    case LightType::Point:
      light.position = l.vec3("position");
      light.intensity = l.rgb("intensity", 0.0f, 1e12f);
      break;
    case LightType::Spot:
      light.position = l.vec3("position");
      light.direction = unitDirection(l, "direction");
      light.intensity = l.rgb("intensity", 0.0f, 1e12f);
      light.coneDeg = l.number("cone_deg", 0.01f, 90.0f, 30.0f);
      light.falloffDeg =
          l.number("falloff_deg", 0.0f, light.coneDeg, std::min(5.0f, light.coneDeg));
      break;
    case LightType::Environment:
      if (l.has("file")) {
        light.file = l.filePath("file");  // read by the scene loader, with the meshes
        light.intensity = l.rgb("radiance", 0.0f, 1e9f, RGB(1.0f));
      } else {
        light.intensity = l.rgb("radiance", 0.0f, 1e9f);
      }
      break;
  }
  l.finish();
  return light;
}

}  // namespace lvox
