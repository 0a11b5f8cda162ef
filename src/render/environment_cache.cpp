#include "src/render/environment_cache.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace lvox {

Vec3 EnvironmentCache::latticeDirection(int j, int n) {
  // z uniform in the cell centres of [-1, 1], azimuth advancing by the golden angle.
  constexpr double kGoldenAngle = 2.399963229728653;  // pi (3 - sqrt 5)
  const double z = 1.0 - (2.0 * j + 1.0) / n;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = kGoldenAngle * j;
  return {static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)),
          static_cast<float>(z)};
}

EnvironmentCache::EnvironmentCache(const RGB& radiance, const Bounds3& bounds, int resolution,
                                   int directions, const Transmittance& transmittance,
                                   const RayTracer* surfaces)
    : grid_(bounds, resolution), surfaces_(surfaces) {
  if (grid_.nodes() == 0 || directions < 1) return;
  if (surfaces_) {
    nearSurface_.assign(grid_.nodes(), 0);
    // The segments from the corners of the box of the node's neighbours (a little larger:
    // a wall on its face counts) to a little past the node, so that a surface through the
    // node, from which the node's own rays would start, counts too.
    const Vec3 h = grid_.spacing() * 1.01f;
    tbb::parallel_for(size_t(0), grid_.nodes(), [&](size_t i) {
      const Vec3 p = grid_.position(i);
      for (int k = 0; k < 8 && !nearSurface_[i]; ++k) {
        const Vec3 corner(k & 1 ? h.x : -h.x, k & 2 ? h.y : -h.y, k & 4 ? h.z : -h.z);
        nearSurface_[i] = surfaces_->blocked(p + corner, p - corner * 0.01f) ? 1 : 0;
      }
    });
  }
  std::vector<Vec3> lattice;
  std::vector<float> basis;  // kShCoefficients per direction
  for (int j = 0; j < directions; ++j) {
    lattice.push_back(latticeDirection(j, directions));
    float y[kShCoefficients];
    shBasis(lattice.back(), kShCoefficients, y);
    basis.insert(basis.end(), y, y + kShCoefficients);
  }
  // Each direction stands for 4 pi / n of the sphere: c_k = (1 / n) sum L T Yhat_k.
  const RGB weight = radiance / static_cast<float>(directions);
  coefficients_.assign(grid_.nodes() * kShCoefficients, RGB(0.0f));
  tbb::parallel_for(tbb::blocked_range<size_t>(0, grid_.nodes(), 16), [&](const auto& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      RGB* c = &coefficients_[i * kShCoefficients];
      for (int j = 0; j < directions; ++j) {
        Ray shadow;
        shadow.origin = grid_.position(i);
        shadow.dir = lattice[static_cast<size_t>(j)];
        shadow.tmin = 0.0f;
        shadow.tmax = kInf;
        const RGB arriving = weight * transmittance(shadow);
        const float* yhat = &basis[static_cast<size_t>(j) * kShCoefficients];
        for (int k = 0; k < kShCoefficients; ++k) c[k] += arriving * yhat[k];
      }
    }
  });
}

bool EnvironmentCache::hidden(const Vec3& x, const Vec3& node) const {
  // A node on a surface (a grid plane along a wall; within rounding of it) took its light
  // from whichever side its rays left by, the wrong one as often as not: it counts as
  // hidden from both, so the segment runs a little past it.
  const Vec3 d = node - x;
  const float reach = length(d);
  const float past = std::max(1e-3f * reach, 2.0f * surfaces_->epsilon());
  return reach > 0.0f && surfaces_->occluded(Ray{x, d / reach, 0.0f, reach + past});
}

void EnvironmentCache::lookup(const Vec3& x, RGB* out) const {
  // Per channel: the mean in its logarithm, the other coefficients as fractions of their
  // node's mean. A node no direction of which reaches the sky (inside a surface: a cloud's
  // transmittance is never exactly 0) is no sample of the light around it and is left out.
  std::fill(out, out + kShCoefficients, RGB(0.0f));
  RGB logMean(0.0f), weights(0.0f);
  grid_.forEachCorner(x, [&](size_t node, float w) {
    if (surfaces_ && nearSurface_[node] && hidden(x, grid_.position(node))) return;
    const RGB* c = &coefficients_[node * kShCoefficients];
    for (int ch = 0; ch < 3; ++ch) {
      if (!(c[0][ch] > 0.0f)) continue;
      weights[ch] += w;
      logMean[ch] += w * std::log(c[0][ch]);
      for (int k = 1; k < kShCoefficients; ++k) out[k][ch] += w * c[k][ch] / c[0][ch];
    }
  });
  for (int ch = 0; ch < 3; ++ch) {
    if (!(weights[ch] > 0.0f)) continue;  // every corner in the dark: all zero
    out[0][ch] = std::exp(logMean[ch] / weights[ch]);
    for (int k = 1; k < kShCoefficients; ++k) out[k][ch] *= out[0][ch] / weights[ch];
  }
}

size_t EnvironmentCache::nodesNearSurfaces() const {
  return static_cast<size_t>(std::count(nearSurface_.begin(), nearSurface_.end(), uint8_t{1}));
}

}  // namespace lvox
