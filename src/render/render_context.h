#pragma once
// What every integrator needs: the world, the render settings, the BVH and the lights, and
// the render's memory budget (none: unchecked, for tools and tests).
#include "src/core/memory_budget.h"
#include "src/geometry/ray_tracer.h"
#include "src/render/light_set.h"
#include "src/render/render_settings.h"
#include "src/world/world.h"

namespace lvox {

struct RenderContext {
  const World& world;
  const RenderSettings& settings;
  const RayTracer& tracer;
  const LightSet& lights;
  MemoryBudget* budget = nullptr;

  // Spawns a ray from a surface point, offset along the normal to avoid self-hits. With a
  // finite `distance` the ray ends short of the point p + dir * distance (a light or an
  // emitter), re-aimed from the offset origin so it cannot reach the target's surface.
  Ray spawn(const Vec3& p, const Vec3& normal, const Vec3& dir, float distance = kInf) const {
    const float eps = tracer.epsilon();
    Ray r;
    r.origin = p + normal * (dot(dir, normal) >= 0.0f ? eps : -eps);
    r.dir = dir;
    r.tmin = 0.0f;
    r.tmax = kInf;
    if (!std::isinf(distance)) {
      const Vec3 toTarget = p + dir * distance - r.origin;
      const float d = length(toTarget);
      r.dir = toTarget / d;
      r.tmax = std::max(0.0f, d * (1.0f - 1e-4f) - 2.0f * eps);
    }
    return r;
  }
};

}  // namespace lvox
