#pragma once
// The scene's one Embree BVH. This header hides Embree: only ray_tracer.cpp includes it.
#include <cstdint>
#include <memory>

#include "src/world/surface_textures.h"
#include "src/world/world.h"

namespace lvox {

struct SurfaceHit {
  float t = kInf;
  uint32_t triangle = 0;
  Vec3 point;
  Vec3 normal;   // geometric, unit, facing the incoming ray (surfaces are two-sided)
  Vec3 shading;  // shading normal (the mesh's smooth normals, else `normal`), same side
  float b1 = 0.0f, b2 = 0.0f;  // barycentrics of the triangle's second and third vertex
};

class RayTracer {
 public:
  // With `textures`, triangles whose material has a cut-out mask are transparent where the
  // mask is below 1/2, for closest hits and shadow rays alike (Embree filter functions,
  // registered only on the geometry that holds such triangles).
  explicit RayTracer(const TriangleMesh& mesh, const SurfaceTextures* textures = nullptr);
  ~RayTracer();
  RayTracer(const RayTracer&) = delete;
  RayTracer& operator=(const RayTracer&) = delete;

  // Nearest hit in (ray.tmin, ray.tmax); false on a miss.
  bool intersect(const Ray& ray, SurfaceHit& hit) const;
  // True if anything blocks the segment origin + t dir, t in (tmin, tmax).
  bool occluded(const Ray& ray) const;
  // True if a surface lies between `from` and `to` (the last 0.1 % of the way left out,
  // so a surface through `to` does not count).
  bool blocked(const Vec3& from, const Vec3& to) const {
    const Vec3 d = to - from;
    const float reach = length(d);
    return reach > 0.0f && occluded(Ray{from, d / reach, 0.0f, 0.999f * reach});
  }
  // Offset that keeps secondary rays off the surface they start on (scales with the scene).
  float epsilon() const { return epsilon_; }
  const TriangleMesh& mesh() const { return mesh_; }
  // The scene's textures (nullptr: none given).
  const SurfaceTextures* textures() const { return textures_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  const TriangleMesh& mesh_;
  const SurfaceTextures* textures_ = nullptr;
  float epsilon_ = 1e-4f;
};

}  // namespace lvox
