#pragma once
// The scene's one Embree BVH. This header hides Embree: only ray_tracer.cpp includes it.
#include <cstdint>
#include <memory>

#include "src/world/world.h"

namespace lvox {

struct SurfaceHit {
  float t = kInf;
  uint32_t triangle = 0;
  Vec3 point;
  Vec3 normal;  // geometric, unit, facing the incoming ray (surfaces are two-sided)
};

class RayTracer {
 public:
  explicit RayTracer(const TriangleMesh& mesh);
  ~RayTracer();
  RayTracer(const RayTracer&) = delete;
  RayTracer& operator=(const RayTracer&) = delete;

  // Nearest hit in (ray.tmin, ray.tmax); false on a miss.
  bool intersect(const Ray& ray, SurfaceHit& hit) const;
  // True if anything blocks the segment origin + t dir, t in (tmin, tmax).
  bool occluded(const Ray& ray) const;
  // Offset that keeps secondary rays off the surface they start on (scales with the scene).
  float epsilon() const { return epsilon_; }
  const TriangleMesh& mesh() const { return mesh_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  const TriangleMesh& mesh_;
  float epsilon_ = 1e-4f;
};

}  // namespace lvox
