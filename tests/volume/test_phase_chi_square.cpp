// Chi-square goodness-of-fit tests of the phase functions' sampling (volume/phase.h):
// sampled directions, binned over the whole sphere in (cos theta, phi), against the
// phase function itself integrated over each cell (method: tests/chi_square.h,
// docs/hardening.md). Light arrives along a skewed direction, so the frame built around
// it is tested too.
#include <gtest/gtest.h>

#include <string>

#include "chi_square.h"
#include "src/core/rng.h"
#include "volume/phase.h"

namespace lvox {
namespace {

constexpr int kSamples = 1000000;  // about 1250 per cell of 20 x 40

void checkPhase(const std::string& name, float g, uint64_t seed) {
  const PhaseFunction phase = PhaseFunction::make(parsePhaseKind(name, "test", "phase"), g);
  const Vec3 wIn = normalize(Vec3(0.3f, -0.5f, 0.8f));
  Rng rng(seed, 0);
  test::SphereHistogram h(20, 40);
  int pdfMismatches = 0;
  for (int i = 0; i < kSamples; ++i) {
    float pdf = 0.0f;
    const Vec3 w = phase.sample(wIn, rng.uniform(), rng.uniform(), pdf);
    h.add(w.x, w.y, w.z);
    // The pdf returned must be the phase function in the sampled direction (the
    // estimators divide by one and multiply by the other); 1e-3 allows float rounding of
    // the frame and of the peak of g = 0.9.
    const float expected = phase.eval(dot(wIn, w));
    if (!(std::abs(pdf - expected) <= 1e-3f * expected)) ++pdfMismatches;
  }
  EXPECT_EQ(pdfMismatches, 0) << name << " g=" << g;
  const auto pdf = [&](double cosTheta, double phi) {
    const double s = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    const Vec3 w(static_cast<float>(s * std::cos(phi)), static_cast<float>(s * std::sin(phi)),
                 static_cast<float>(cosTheta));
    return static_cast<double>(phase.eval(std::clamp(dot(wIn, w), -1.0f, 1.0f)));
  };
  const std::vector<double> expected = h.expected(pdf, kSamples);
  // The phase function is normalised: the cells' probabilities add up to 1.
  double total = 0.0;
  for (double e : expected) total += e;
  EXPECT_NEAR(total / kSamples, 1.0, 1e-4) << name << " g=" << g;
  const auto r = test::chiSquareTest(h.counts, expected);
  EXPECT_TRUE(r.accepted()) << name << " g=" << g << ": " << r.describe();
}

class PhaseChiSquare : public testing::TestWithParam<float> {};

TEST_P(PhaseChiSquare, HenyeyGreenstein) { checkPhase("hg", GetParam(), 10); }
TEST_P(PhaseChiSquare, Schlick) { checkPhase("schlick", GetParam(), 11); }

// Backward, isotropic (g = 0 is the isotropic function), forward and strongly forward.
INSTANTIATE_TEST_SUITE_P(G, PhaseChiSquare, testing::Values(-0.7f, -0.3f, 0.0f, 0.5f, 0.9f),
                         [](const testing::TestParamInfo<float>& param) {
                           const int percent = static_cast<int>(std::lround(param.param * 100));
                           return (percent < 0 ? "minus" : "") + std::to_string(std::abs(percent));
                         });

}  // namespace
}  // namespace lvox
