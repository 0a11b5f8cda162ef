#include "pointcloud/buried_surfels.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

#include "pointcloud/gather.h"
#include "src/core/rng.h"
#include "src/core/sampling.h"

namespace lvox {
namespace {

// True when every stratified cosine-weighted probe from p (side n) hits within reach.
bool sideEnclosed(const RayTracer& tracer, const Vec3& p, const Vec3& n,
                  const BuriedSurfelSettings& settings, Rng& rng) {
  int rows, cols;
  strataGrid(settings.raysPerSide, rows, cols);
  const Frame frame(n);
  const float eps = tracer.epsilon();
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const float u1 = (static_cast<float>(r) + rng.uniform()) / static_cast<float>(rows);
      const float u2 = (static_cast<float>(c) + rng.uniform()) / static_cast<float>(cols);
      const Ray probe{p + n * eps, frame.toWorld(cosineHemisphere(u1, u2)), 0.0f, settings.reach};
      if (!tracer.occluded(probe)) return false;
    }
  return true;
}

// True when the segment from the viewpoint to p, on the side n, is unoccluded.
bool seenFrom(const RayTracer& tracer, const Vec3& viewpoint, const Vec3& p, const Vec3& n) {
  const Vec3 target = p + n * tracer.epsilon();
  const Vec3 d = target - viewpoint;
  const float len = length(d);
  if (!(len > 0.0f)) return true;
  return !tracer.occluded(Ray{viewpoint, d / len, 0.0f, len * (1.0f - 1e-4f)});
}

bool isEnclosed(const RayTracer& tracer, const Vec3& p, const Vec3& n,
                const BuriedSurfelSettings& settings, Rng& rng) {
  return sideEnclosed(tracer, p, n, settings, rng) &&
         !(settings.viewpoint && seenFrom(tracer, *settings.viewpoint, p, n));
}

}  // namespace

size_t removeBuriedSurfels(SurfelSet& surfels, const RayTracer& tracer,
                           const BuriedSurfelSettings& settings) {
  markEnclosedSides(surfels, tracer, settings, 0, surfels.size());
  return removeEnclosedSurfels(surfels);
}

void markEnclosedSides(SurfelSet& surfels, const RayTracer& tracer,
                       const BuriedSurfelSettings& settings, size_t begin, size_t end) {
  const size_t stop = std::min(end, surfels.size());
  if (begin >= stop) return;
  tbb::parallel_for(begin, stop, [&](size_t i) {
    Rng rng(settings.seed ^ 0xb0c1edull, i);
    const bool front = isEnclosed(tracer, surfels.position[i], surfels.normal[i], settings, rng);
    const bool back = isEnclosed(tracer, surfels.position[i], -surfels.normal[i], settings, rng);
    surfels.enclosedSides[i] = static_cast<uint8_t>((front ? 1u : 0u) | (back ? 2u : 0u));
  });
}

size_t removeEnclosedSurfels(SurfelSet& surfels) {
  std::vector<uint32_t> keep;
  keep.reserve(surfels.size());
  for (size_t i = 0; i < surfels.size(); ++i)
    if (surfels.enclosedSides[i] != 3u) keep.push_back(static_cast<uint32_t>(i));
  const size_t removed = surfels.size() - keep.size();
  if (removed > 0) surfels.permute(keep);
  return removed;
}

}  // namespace lvox
