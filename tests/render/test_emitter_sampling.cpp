// Emitters are sampled by solid angle where they subtend enough of it
// (src/render/light_set.h, src/core/spherical_triangle.h). Sampled by area, a point at
// height h below a lamp gets samples of cos/r^2 up to 1/h^2, whose variance grows without
// bound as h -> 0 (a medium touching a lamp made MC's error fall as N^-1/3); by solid angle
// every sample is bounded. Here: the irradiance just below a square lamp against its
// closed form, and its spread.
#include <gtest/gtest.h>

#include <cmath>

#include "square_lamp.h"
#include "src/render/light_set.h"

namespace lvox {
namespace {

// Irradiance from a uniform emitter of radiance L covering an a x b rectangle seen from
// height h above its corner (the classic differential-area form factor, times pi L).
double cornerIrradiance(double a, double b, double h, double L) {
  const double x = a / h, y = b / h;
  const double sx = std::sqrt(1.0 + x * x), sy = std::sqrt(1.0 + y * y);
  return 0.5 * L * (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy));
}

TEST(EmitterSampling, IrradianceJustBelowALampIsExactAndBounded) {
  const World world = test::squareLampWorld(3.0f);
  const int samples = 16, calls = 4000;
  const LightSet lights(world, samples);
  const Vec3 n(0.0f, 0.0f, 1.0f);
  for (const float h : {0.5f, 1e-2f, 1e-3f}) {
    const Vec3 p(0.0f, 0.0f, 1.0f - h);
    const double exact = 4.0 * cornerIrradiance(1.0, 1.0, h, 3.0);
    double sum = 0.0, sum2 = 0.0, largest = 0.0;
    for (int call = 0; call < calls; ++call) {
      Rng rng(9, static_cast<uint64_t>(call));
      double e = 0.0;
      lights.forEachAreaSample(p, &n, rng, [&](const LightSample& s) {
        const double x = s.radiance.x * std::max(0.0f, dot(s.wi, n));
        largest = std::max(largest, x * samples);
        e += x;
      });
      sum += e;
      sum2 += e * e;
    }
    const double mean = sum / calls;
    const double rms = std::sqrt(std::max(0.0, sum2 / calls - mean * mean));
    // Unbiased: within 5 standard errors (and the spread itself is small).
    EXPECT_NEAR(mean, exact, 5.0 * rms / std::sqrt(double(calls)) + 1e-6 * exact) << "h " << h;
    EXPECT_LT(rms, 0.05 * exact) << "h " << h;
    // One sample of one triangle is at most L times its solid angle (< 2 pi) over its
    // share of the area (1/2); by area it would reach L * 4 / h^2.
    EXPECT_LE(largest, 3.0 * 2.0 * kPi / 0.5 * 1.0001) << "h " << h;
  }
}

}  // namespace
}  // namespace lvox
