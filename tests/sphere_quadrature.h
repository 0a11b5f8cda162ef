#pragma once
// The mean of a function over the unit sphere by quadrature, for tests of directional
// quantities (spherical harmonics, phase functions).
#include <algorithm>
#include <cmath>

#include "src/core/math.h"

namespace lvox::test {

// Mean over the sphere of f(w) by the midpoint rule in (cos theta, phi): exact to well
// under 1e-4 for the smooth integrands below.
template <class F>
double sphereMean(F&& f, int nMu = 800, int nPhi = 400) {
  double sum = 0.0;
  for (int i = 0; i < nMu; ++i) {
    const double mu = -1.0 + (i + 0.5) * 2.0 / nMu;
    const double s = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    for (int j = 0; j < nPhi; ++j) {
      const double phi = (j + 0.5) * 2.0 * M_PI / nPhi;
      sum += f(Vec3(static_cast<float>(s * std::cos(phi)), static_cast<float>(s * std::sin(phi)),
                    static_cast<float>(mu)));
    }
  }
  return sum / (static_cast<double>(nMu) * nPhi);
}

}  // namespace lvox::test
