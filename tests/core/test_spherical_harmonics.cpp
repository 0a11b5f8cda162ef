#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sphere_quadrature.h"
#include "src/core/spherical_harmonics.h"

namespace lvox {
namespace {

// The basis is orthonormal under the mean over the sphere (hence c_k = mean of f Yhat_k
// and f = sum c_k Yhat_k), and its first function is 1.
TEST(SphericalHarmonics, OrthonormalUnderTheMeanOverTheSphere) {
  for (int a = 0; a < kShCoefficients; ++a)
    for (int b = a; b < kShCoefficients; ++b) {
      const double m = test::sphereMean([&](const Vec3& w) {
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
    const double ck = test::sphereMean([&](const Vec3& w) {
      float y[kShCoefficients];
      shBasis(w, kShCoefficients, y);
      return f(w) * y[k];
    });
    c[static_cast<size_t>(k)] = RGB(static_cast<float>(ck));
  }
  EXPECT_NEAR(c[0].x, 2.0f, 1e-4f);  // the mean
  for (const Vec3& w :
       {Vec3(0, 0, 1), normalize(Vec3(1, 1, 0)), normalize(Vec3(-0.3f, 0.5f, -0.8f))}) {
    float y[kShCoefficients];
    shBasis(w, kShCoefficients, y);
    EXPECT_NEAR(shDot(c.data(), y, kShCoefficients).x, f(w), 1e-3) << w;
  }
}

}  // namespace
}  // namespace lvox
