#include "src/render/transmittance_cache.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace lvox {

Ray TransmittanceCache::shadowRay(const Light& light, const Vec3& x) {
  Ray r;
  r.origin = x;
  r.tmin = 0.0f;
  if (light.type == LightType::Directional) {
    r.dir = -light.direction;
    r.tmax = kInf;
    return r;
  }
  const Vec3 toLight = light.position - x;
  const float d = length(toLight);
  r.dir = d > 0.0f ? toLight / d : Vec3(0.0f, 1.0f, 0.0f);
  r.tmax = d * (1.0f - 1e-4f);
  return r;
}

size_t TransmittanceCache::nodeCount(const Bounds3& bounds, int resolution) {
  return NodeGrid(bounds, resolution).nodes();
}

TransmittanceCache::TransmittanceCache(const std::vector<Light>& lights, const Bounds3& bounds,
                                       int resolution, const Transmittance& transmittance)
    : grid_(bounds, resolution) {
  if (grid_.nodes() == 0) return;
  grids_.resize(lights.size());
  for (size_t l = 0; l < lights.size(); ++l) {
    if (lights[l].type == LightType::Environment) continue;
    std::vector<RGB>& grid = grids_[l];
    grid.assign(nodes(), RGB(1.0f));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, grid.size(), 64), [&](const auto& range) {
      for (size_t i = range.begin(); i != range.end(); ++i)
        grid[i] = transmittance(shadowRay(lights[l], grid_.position(i)));
    });
  }
}

RGB TransmittanceCache::lookup(size_t light, const Vec3& x) const {
  // In the logarithm: transmittance falls exponentially, and linear interpolation of a
  // convex function overestimates it (docs/results.md, "Shadow transmittance cache"). A
  // node whose transmittance underflowed to 0 counts as 1e-30.
  const std::vector<RGB>& grid = grids_[light];
  RGB logT(0.0f);
  grid_.forEachCorner(x, [&](size_t node, float w) {
    for (int c = 0; c < 3; ++c) logT[c] += w * std::log(std::max(grid[node][c], 1e-30f));
  });
  return RGB(std::exp(logT.x), std::exp(logT.y), std::exp(logT.z));
}

size_t TransmittanceCache::memoryBytes() const {
  size_t bytes = 0;
  for (const auto& g : grids_) bytes += g.size() * sizeof(RGB);
  return bytes;
}

}  // namespace lvox
