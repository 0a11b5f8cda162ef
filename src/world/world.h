#pragma once
// The world of a scene: camera, materials, surfaces and lights, after validation. Geometry
// is flattened into one triangle mesh in world space.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "src/core/math.h"
#include "src/world/environment_map.h"

namespace lvox {

struct Camera {
  Vec3 position{0, 0, 5};
  Vec3 lookAt{0, 0, 0};
  Vec3 up{0, 1, 0};
  float vfovDeg = 45.0f;
  int width = 512;
  int height = 512;

  // Ray through image-plane position (px, py) in pixels from the top-left corner.
  Ray generateRay(float px, float py) const;
};

// An image a material reads, and where it was named (for errors and the scene's inputs).
struct TextureFile {
  std::string path;     // absolute or relative to the working directory
  std::string namedBy;  // the MTL, glTF or scene file that names it
  std::string field;    // e.g. "material 'stone': map_Kd"
  bool operator==(const TextureFile&) const = default;
};

struct Material {
  std::string name;
  RGB albedo{0.8f, 0.8f, 0.8f};    // with an albedo map: the factor it is multiplied by
  RGB emission{0.0f, 0.0f, 0.0f};  // emitted radiance, W/(m^2 sr)
  int albedoMap = -1;              // index into World::textures, -1: none
  int opacityMap = -1;             // cut-out mask (MTL map_d): opacity below 1/2 is a hole
  bool isEmissive() const { return !isBlack(emission); }
};

// Per-vertex attributes of one triangle, as a file gives them.
struct TriangleAttributes {
  const Vec2* uv = nullptr;      // 3 texture coordinates, or none
  const Vec3* normal = nullptr;  // 3 shading normals (unit), or none
};

// All triangles of the scene in world space; one material index per triangle.
struct TriangleMesh {
  std::vector<Vec3> positions;
  std::vector<uint32_t> indices;           // 3 per triangle
  std::vector<uint32_t> triangleMaterial;  // 1 per triangle
  // Per vertex, each empty while no triangle has one: texture coordinates ((0, 0) where a
  // triangle has none) and shading normals (the geometric normal where a triangle has none).
  std::vector<Vec2> uvs;
  std::vector<Vec3> normals;
  size_t triangleCount() const { return triangleMaterial.size(); }
  Vec3 vertex(size_t tri, int k) const { return positions[indices[3 * tri + k]]; }
  // Texture coordinates at barycentrics (b1, b2) of the triangle's second and third vertex.
  Vec2 uvAt(size_t tri, float b1, float b2) const {
    const Vec2& a = uvs[indices[3 * tri]];
    return a + (uvs[indices[3 * tri + 1]] - a) * b1 + (uvs[indices[3 * tri + 2]] - a) * b2;
  }
  // Unit shading normal at barycentrics (b1, b2); needs `normals`.
  Vec3 shadingNormalAt(size_t tri, float b1, float b2) const {
    return normalize(normals[indices[3 * tri]] * (1.0f - b1 - b2) +
                     normals[indices[3 * tri + 1]] * b1 + normals[indices[3 * tri + 2]] * b2);
  }
  // Barycentrics (b1, b2) of the point of the triangle's plane nearest to p.
  Vec2 barycentricOf(size_t tri, const Vec3& p) const;
  // Sum of the triangles' areas, accumulated in double.
  double area() const {
    double a = 0.0;
    for (size_t t = 0; t < triangleCount(); ++t)
      a += 0.5 * length(cross(vertex(t, 1) - vertex(t, 0), vertex(t, 2) - vertex(t, 0)));
    return a;
  }
};

enum class LightType { Directional, Point, Spot, Environment };

struct Light {
  LightType type = LightType::Point;
  Vec3 position{0, 0, 0};
  Vec3 direction{0, -1, 0};  // direction of travel (directional, spot axis), unit
  RGB intensity{0, 0, 0};    // W/sr for point/spot, W/m^2 irradiance for directional,
                             // W/(m^2 sr) radiance for the environment
  float coneDeg = 30.0f;     // spot: angle from the axis to the edge
  float falloffDeg = 5.0f;   // spot: width of the smooth edge
  std::string file;          // environment: a lat-long map (then `intensity` scales it)

  // Spot falloff: 1 inside cone-falloff, smoothstep in cos to 0 at the cone edge.
  float spotFactor(const Vec3& dirFromLight) const;
};

// What the camera sees and what lights it: surfaces with their materials, and the lights.
// Media are described by the volume library (volume/media/medium_desc.h) and every
// library's settings by that library; src/scene composes them from a scene file.
struct World {
  Camera camera;
  std::vector<Material> materials;
  TriangleMesh mesh;
  std::vector<Light> lights;
  std::vector<TextureFile> textures;  // every image materials read, each once
  // The environment lights' lat-long map (at most one), loaded with the scene.
  std::shared_ptr<const EnvironmentMap> environmentMap;

  // Index of `file` in `textures`, added if new.
  int textureIndex(const TextureFile& file);

  Bounds3 bounds() const;  // of the mesh
};

}  // namespace lvox
