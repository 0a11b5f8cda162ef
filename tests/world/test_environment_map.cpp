// The lat-long environment map's importance sampler: a chi-square test of where its
// samples land, its solid-angle pdf against the sampling density (E[1/pdf] = 4 pi), and
// radiance lookups by direction.
#include <gtest/gtest.h>

#include "chi_square.h"
#include "src/core/rng.h"
#include "src/world/environment_map.h"

namespace lvox {
namespace {

// 16 x 8 texels: a bright "sun" texel, a dim gradient, and a black row near the nadir.
EnvironmentMap testMap() {
  std::vector<RGB> t(16 * 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x)
      t[y * 16 + x] = RGB(0.1f + 0.05f * float(x), 0.2f, 0.3f + 0.02f * float(y));
  for (int x = 0; x < 16; ++x) t[6 * 16 + x] = RGB(0.0f);
  t[2 * 16 + 5] = RGB(40.0f, 30.0f, 20.0f);
  return EnvironmentMap(16, 8, std::move(t));
}

TEST(EnvironmentMap, SamplesFollowRadianceTimesSolidAngle) {
  const EnvironmentMap map = testMap();
  // Expected texel probabilities: mean radiance x the texel's solid angle (exact:
  // 2 pi / w x (cos theta0 - cos theta1)), normalised. The sampler weights by sin(theta)
  // at the texel's centre, which is not the exact solid angle, so the test uses the
  // sampler's documented weights: mean radiance x sin(theta_centre).
  std::vector<double> weights(16 * 8);
  double total = 0.0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) {
      const Vec3 dir = [&] {
        const double theta = kPi * (y + 0.5) / 8, phi = 2 * kPi * ((x + 0.5) / 16 - 0.5);
        return Vec3(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
                    float(-std::sin(theta) * std::cos(phi)));
      }();
      weights[y * 16 + x] = average(map.radiance(dir)) * std::sin(kPi * (y + 0.5) / 8);
      total += weights[y * 16 + x];
    }
  constexpr int kSamples = 400000;
  std::vector<double> observed(16 * 8, 0.0), expected(16 * 8);
  for (size_t i = 0; i < expected.size(); ++i) expected[i] = weights[i] / total * kSamples;
  Rng rng(7, 0);
  double inversePdf = 0.0;
  int inconsistent = 0;
  for (int i = 0; i < kSamples; ++i) {
    float pdf;
    const Vec3 d = map.sample(rng.uniform(), rng.uniform(), pdf);
    ASSERT_GT(pdf, 0.0f);
    const float u = 0.5f + std::atan2(d.x, -d.z) / (2 * kPi);
    const float v = std::acos(std::clamp(d.y, -1.0f, 1.0f)) / kPi;
    const int x = std::clamp(int(u * 16), 0, 15), y = std::clamp(int(v * 8), 0, 7);
    observed[y * 16 + x] += 1.0;
    inversePdf += 1.0 / pdf;
    if (!(std::abs(map.pdf(d) - pdf) <= 1e-2f * pdf)) ++inconsistent;
  }
  const auto r = test::chiSquareTest(observed, expected);
  EXPECT_TRUE(r.accepted()) << r.describe();
  EXPECT_EQ(observed[6 * 16 + 3], 0.0) << "a black texel was sampled";
  // pdf(dir) is the density sample() drew it with, but for directions that float rounding
  // puts across a texel border (about 4 in 10^4 here).
  EXPECT_LE(inconsistent, kSamples / 1000);
  // E[1/pdf] over the sampled directions is the solid angle where the pdf is positive:
  // the sphere minus the black row (2 pi (cos(6 pi/8) - cos(7 pi/8))).
  const double support = 4 * kPi - 2 * kPi * (std::cos(6 * kPi / 8) - std::cos(7 * kPi / 8));
  EXPECT_NEAR(inversePdf / kSamples, support, 0.01 * support);
}

TEST(EnvironmentMap, RadianceByDirection) {
  const EnvironmentMap map = testMap();
  EXPECT_EQ(map.radiance(Vec3(0, 1, 0)).z, 0.3f);                              // zenith: row 0
  EXPECT_EQ(map.radiance(Vec3(0, -1, 0)).z, 0.3f + 0.02f * 7);                 // nadir: last row
  EXPECT_EQ(map.radiance(Vec3(0, 0, -1)).x, 0.1f + 0.05f * 8);                 // -z: column w/2
  EXPECT_EQ(map.radiance(normalize(Vec3(0.01f, 0, 1))).x, 0.1f + 0.05f * 15);  // +z, +x side
  EXPECT_FALSE(map.black());
  EXPECT_TRUE(EnvironmentMap(2, 1, {RGB(0.0f), RGB(0.0f)}).black());
}

}  // namespace
}  // namespace lvox
