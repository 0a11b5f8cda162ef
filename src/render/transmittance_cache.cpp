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
  if (bounds.empty() || resolution < 1) return 0;
  const Vec3 extent = bounds.diagonal();
  const float side = std::max({extent.x, extent.y, extent.z}) / static_cast<float>(resolution);
  size_t n = 1;
  for (int a = 0; a < 3; ++a)
    n *= static_cast<size_t>(std::max(2, static_cast<int>(std::ceil(extent[a] / side)) + 1));
  return n;
}

TransmittanceCache::TransmittanceCache(const std::vector<Light>& lights, const Bounds3& bounds,
                                       int resolution, const Transmittance& transmittance)
    : bounds_(bounds) {
  if (bounds.empty() || resolution < 1) return;
  const Vec3 extent = bounds.diagonal();
  const float side = std::max({extent.x, extent.y, extent.z}) / static_cast<float>(resolution);
  for (int a = 0; a < 3; ++a) {
    n_[a] = std::max(2, static_cast<int>(std::ceil(extent[a] / side)) + 1);
    cell_[a] = extent[a] > 0.0f ? extent[a] / static_cast<float>(n_[a] - 1) : 1.0f;
  }
  grids_.resize(lights.size());
  for (size_t l = 0; l < lights.size(); ++l) {
    if (lights[l].type == LightType::Environment) continue;
    std::vector<RGB>& grid = grids_[l];
    grid.assign(nodes(), RGB(1.0f));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, grid.size(), 64), [&](const auto& range) {
      for (size_t i = range.begin(); i != range.end(); ++i) {
        const size_t x = i % static_cast<size_t>(n_[0]);
        const size_t y = (i / static_cast<size_t>(n_[0])) % static_cast<size_t>(n_[1]);
        const size_t z = i / (static_cast<size_t>(n_[0]) * static_cast<size_t>(n_[1]));
        const Vec3 p = bounds_.lo + mul(cell_, Vec3(static_cast<float>(x), static_cast<float>(y),
                                                    static_cast<float>(z)));
        grid[i] = transmittance(shadowRay(lights[l], p));
      }
    });
  }
}

RGB TransmittanceCache::lookup(size_t light, const Vec3& x) const {
  const std::vector<RGB>& grid = grids_[light];
  float f[3];
  int i[3];
  for (int a = 0; a < 3; ++a) {
    const float u =
        std::clamp((x[a] - bounds_.lo[a]) / cell_[a], 0.0f, static_cast<float>(n_[a] - 1));
    i[a] = std::min(static_cast<int>(u), n_[a] - 2);
    f[a] = u - static_cast<float>(i[a]);
  }
  // In the logarithm: transmittance falls exponentially, and linear interpolation of a
  // convex function overestimates it (docs/results.md, "Shadow transmittance cache"). A
  // node whose transmittance underflowed to 0 counts as 1e-30.
  RGB logT(0.0f);
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
    const float w = (dx ? f[0] : 1.0f - f[0]) * (dy ? f[1] : 1.0f - f[1]) *
                    (dz ? f[2] : 1.0f - f[2]);
    if (w == 0.0f) continue;
    const RGB& t = grid[(static_cast<size_t>(i[2] + dz) * static_cast<size_t>(n_[1]) +
                         static_cast<size_t>(i[1] + dy)) *
                            static_cast<size_t>(n_[0]) +
                        static_cast<size_t>(i[0] + dx)];
    for (int c = 0; c < 3; ++c) logT[c] += w * std::log(std::max(t[c], 1e-30f));
  }
  return RGB(std::exp(logT.x), std::exp(logT.y), std::exp(logT.z));
}

size_t TransmittanceCache::memoryBytes() const {
  size_t bytes = 0;
  for (const auto& g : grids_) bytes += g.size() * sizeof(RGB);
  return bytes;
}

}  // namespace lvox
