#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "src/core/spherical_harmonics.h"

namespace lvox {
namespace {

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

// The basis is orthonormal under the mean over the sphere (hence c_k = mean of f Yhat_k
// and f = sum c_k Yhat_k), and its first function is 1.
TEST(SphericalHarmonics, OrthonormalUnderTheMeanOverTheSphere) {
  for (int a = 0; a < kShCoefficients; ++a)
    for (int b = a; b < kShCoefficients; ++b) {
      const double m = sphereMean([&](const Vec3& w) {
        float y[kShCoefficients];
        shBasis(w, kShCoefficients, y);
        return static_cast<double>(y[a]) * y[b];
      });
      EXPECT_NEAR(m, a == b ? 1.0 : 0.0, 2e-4) << a << " " << b;
    }
}

// A function in the span is recovered from its projection: f = 2 + 0.5 z - 0.3 x y.
TEST(SphericalHarmonics, ProjectionRecoversAFunctionOfTheFirstBands) {
  auto f = [](const Vec3& w) { return 2.0 + 0.5 * w.z - 0.3 * w.x * w.y; };
  std::vector<RGB> c(kShCoefficients, RGB(0.0f));
  for (int k = 0; k < kShCoefficients; ++k) {
    const double ck = sphereMean([&](const Vec3& w) {
      float y[kShCoefficients];
      shBasis(w, kShCoefficients, y);
      return f(w) * y[k];
    });
    c[static_cast<size_t>(k)] = RGB(static_cast<float>(ck));
  }
  EXPECT_NEAR(c[0].x, 2.0f, 1e-4f);  // the mean
  for (const Vec3& w : {Vec3(0, 0, 1), normalize(Vec3(1, 1, 0)), normalize(Vec3(-0.3f, 0.5f, -0.8f))}) {
    float y[kShCoefficients];
    shBasis(w, kShCoefficients, y);
    EXPECT_NEAR(shDot(c.data(), y, kShCoefficients).x, f(w), 1e-3) << w;
  }
}

}  // namespace
}  // namespace lvox
