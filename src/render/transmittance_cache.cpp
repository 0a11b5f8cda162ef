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
  auto at = [&](int dx, int dy, int dz) {
    return grid[(static_cast<size_t>(i[2] + dz) * n_[1] + static_cast<size_t>(i[1] + dy)) * n_[0] +
                static_cast<size_t>(i[0] + dx)];
  };
  auto lerp = [](const RGB& a, const RGB& b, float t) { return a + (b - a) * t; };
  const RGB c00 = lerp(at(0, 0, 0), at(1, 0, 0), f[0]), c10 = lerp(at(0, 1, 0), at(1, 1, 0), f[0]);
  const RGB c01 = lerp(at(0, 0, 1), at(1, 0, 1), f[0]), c11 = lerp(at(0, 1, 1), at(1, 1, 1), f[0]);
  return lerp(lerp(c00, c10, f[1]), lerp(c01, c11, f[1]), f[2]);
}

size_t TransmittanceCache::memoryBytes() const {
  size_t bytes = 0;
  for (const auto& g : grids_) bytes += g.size() * sizeof(RGB);
  return bytes;
}

}  // namespace lvox
