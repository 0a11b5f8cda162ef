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
                                   int directions, const Transmittance& transmittance)
    : bounds_(bounds) {
  if (bounds.empty() || resolution < 1 || directions < 1) return;
  const Vec3 extent = bounds.diagonal();
  const float side = std::max({extent.x, extent.y, extent.z}) / static_cast<float>(resolution);
  for (int a = 0; a < 3; ++a) {
    n_[a] = std::max(2, static_cast<int>(std::ceil(extent[a] / side)) + 1);
    cell_[a] = extent[a] > 0.0f ? extent[a] / static_cast<float>(n_[a] - 1) : 1.0f;
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
  coefficients_.assign(nodes() * kShCoefficients, RGB(0.0f));
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nodes(), 16), [&](const auto& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const size_t x = i % static_cast<size_t>(n_[0]);
      const size_t y = (i / static_cast<size_t>(n_[0])) % static_cast<size_t>(n_[1]);
      const size_t z = i / (static_cast<size_t>(n_[0]) * static_cast<size_t>(n_[1]));
      const Vec3 p = bounds_.lo + mul(cell_, Vec3(static_cast<float>(x), static_cast<float>(y),
                                                  static_cast<float>(z)));
      RGB* c = &coefficients_[i * kShCoefficients];
      for (int j = 0; j < directions; ++j) {
        Ray shadow;
        shadow.origin = p;
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

void EnvironmentCache::lookup(const Vec3& x, RGB* out) const {
  float f[3];
  int i[3];
  for (int a = 0; a < 3; ++a) {
    const float u =
        std::clamp((x[a] - bounds_.lo[a]) / cell_[a], 0.0f, static_cast<float>(n_[a] - 1));
    i[a] = std::min(static_cast<int>(u), n_[a] - 2);
    f[a] = u - static_cast<float>(i[a]);
  }
  // Per channel: the mean in its logarithm, the other coefficients as fractions of their
  // node's mean. A node no direction of which reaches the sky (inside a surface: a cloud's
  // transmittance is never exactly 0) is no sample of the light around it and is left out.
  std::fill(out, out + kShCoefficients, RGB(0.0f));
  RGB logMean(0.0f), weights(0.0f);
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
    const float w =
        (dx ? f[0] : 1.0f - f[0]) * (dy ? f[1] : 1.0f - f[1]) * (dz ? f[2] : 1.0f - f[2]);
    if (w == 0.0f) continue;
    const size_t node = (static_cast<size_t>(i[2] + dz) * static_cast<size_t>(n_[1]) +
                         static_cast<size_t>(i[1] + dy)) *
                            static_cast<size_t>(n_[0]) +
                        static_cast<size_t>(i[0] + dx);
    const RGB* c = &coefficients_[node * kShCoefficients];
    for (int ch = 0; ch < 3; ++ch) {
      if (!(c[0][ch] > 0.0f)) continue;
      weights[ch] += w;
      logMean[ch] += w * std::log(c[0][ch]);
      for (int k = 1; k < kShCoefficients; ++k) out[k][ch] += w * c[k][ch] / c[0][ch];
    }
  }
  for (int ch = 0; ch < 3; ++ch) {
    if (!(weights[ch] > 0.0f)) continue;  // every corner in the dark: all zero
    out[0][ch] = std::exp(logMean[ch] / weights[ch]);
    for (int k = 1; k < kShCoefficients; ++k) out[k][ch] *= out[0][ch] / weights[ch];
  }
}

}  // namespace lvox
