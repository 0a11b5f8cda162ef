#pragma once
// The world of a scene: camera, materials, surfaces and lights, after validation. Geometry
// is flattened into one triangle mesh in world space.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "src/core/math.h"

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

struct Material {
  std::string name;
  RGB albedo{0.8f, 0.8f, 0.8f};
  RGB emission{0.0f, 0.0f, 0.0f};  // emitted radiance, W/(m^2 sr)
  bool isEmissive() const { return !isBlack(emission); }
};

// All triangles of the scene in world space; one material index per triangle.
struct TriangleMesh {
  std::vector<Vec3> positions;
  std::vector<uint32_t> indices;           // 3 per triangle
  std::vector<uint32_t> triangleMaterial;  // 1 per triangle
  size_t triangleCount() const { return triangleMaterial.size(); }
  Vec3 vertex(size_t tri, int k) const { return positions[indices[3 * tri + k]]; }
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

  Bounds3 bounds() const;  // of the mesh
};

}  // namespace lvox
