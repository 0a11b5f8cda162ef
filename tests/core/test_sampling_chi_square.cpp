// Chi-square goodness-of-fit tests of the warps of src/core/sampling.h (method:
// tests/chi_square.h, docs/hardening.md), and of the test itself: its p-values against
// tabulated quantiles, and that it rejects samples drawn from a pdf other than the claimed
// one.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "chi_square.h"
#include "src/core/rng.h"
#include "src/core/sampling.h"

namespace lvox {
namespace {

using test::chiSquareTest;
using test::LineHistogram;
using test::SphereHistogram;

constexpr double kPi = std::numbers::pi;
// 10^6 samples in 20 x 40 cells: about 1250 per cell, so a 3 % error of a sampler's
// density over a band of cells shows as a chi-square far beyond the threshold.
constexpr int kSamples = 1000000;

TEST(ChiSquare, PValuesMatchTabulatedQuantiles) {
  // Upper 5 % and 1 % quantiles of the chi-square distribution (NIST/SEMATECH tables).
  EXPECT_NEAR(test::chiSquarePValue(3.841, 1), 0.05, 2e-5);
  EXPECT_NEAR(test::chiSquarePValue(18.307, 10), 0.05, 2e-5);
  EXPECT_NEAR(test::chiSquarePValue(23.209, 10), 0.01, 2e-5);
  EXPECT_NEAR(test::chiSquarePValue(124.342, 100), 0.05, 2e-5);
  EXPECT_NEAR(test::chiSquarePValue(135.807, 100), 0.01, 2e-5);
  // Two degrees of freedom: Q(1, x/2) = exp(-x/2) exactly.
  for (double x : {0.1, 1.0, 7.0, 40.0})
    EXPECT_NEAR(test::chiSquarePValue(x, 2), std::exp(-0.5 * x),
                1e-12 * std::exp(-0.5 * x) + 1e-15);
}

TEST(ChiSquare, PoolsSparseCellsAndRejectsSamplesOutsideTheSupport) {
  // Three cells with expected counts below 5 pool into one of 9 (observed 9): no excess.
  const auto pooled = chiSquareTest({100, 2, 3, 4, 95}, {100, 3, 3, 3, 100});
  EXPECT_EQ(pooled.dof, 2);
  EXPECT_NEAR(pooled.statistic, 0.25, 1e-12);
  EXPECT_TRUE(pooled.accepted());
  // Samples in a cell of zero probability fail whatever the statistic.
  EXPECT_FALSE(chiSquareTest({100, 100, 50}, {125, 125, 0}).accepted());
}

// The test can fail: cosine-weighted samples against the uniform hemisphere's pdf (a
// gross error), and uniform sphere samples against a density only 4 % off at the poles.
TEST(ChiSquare, RejectsWrongPdfs) {
  Rng rng(1, 0);
  SphereHistogram cosine(20, 40), sphere(20, 40);
  for (int i = 0; i < kSamples; ++i) {
    const Vec3 c = cosineHemisphere(rng.uniform(), rng.uniform());
    cosine.add(c.x, c.y, c.z);
    const Vec3 s = uniformSphere(rng.uniform(), rng.uniform());
    sphere.add(s.x, s.y, s.z);
  }
  const auto uniformHemisphere = [](double z, double) { return z > 0.0 ? 0.5 / kPi : 0.0; };
  const auto gross = chiSquareTest(cosine.counts, cosine.expected(uniformHemisphere, kSamples));
  EXPECT_FALSE(gross.accepted()) << gross.describe();
  EXPECT_LT(gross.pValue, 1e-100);
  // (1 + 0.04 P2(z)) / (4 pi) integrates to 1: a 4 % excess at the poles, 2 % deficit at
  // the equator.
  const auto subtle = [](double z, double) {
    return (1.0 + 0.02 * (3.0 * z * z - 1.0)) / (4.0 * kPi);
  };
  const auto slight = chiSquareTest(sphere.counts, sphere.expected(subtle, kSamples));
  EXPECT_FALSE(slight.accepted()) << slight.describe();
  // The right pdf passes on the same samples.
  const auto right = chiSquareTest(
      sphere.counts, sphere.expected([](double, double) { return 1.0 / (4.0 * kPi); }, kSamples));
  EXPECT_TRUE(right.accepted()) << right.describe();
}

TEST(SamplingChiSquare, CosineHemisphere) {
  Rng rng(2, 0);
  SphereHistogram h(20, 40);
  for (int i = 0; i < kSamples; ++i) {
    const Vec3 d = cosineHemisphere(rng.uniform(), rng.uniform());
    h.add(d.x, d.y, d.z);
    ASSERT_NEAR(length(d), 1.0f, 1e-5f);
  }
  const auto pdf = [](double z, double) {
    return z > 0.0 ? static_cast<double>(cosineHemispherePdf(static_cast<float>(z))) : 0.0;
  };
  const auto r = chiSquareTest(h.counts, h.expected(pdf, kSamples));
  EXPECT_TRUE(r.accepted()) << r.describe();
}

TEST(SamplingChiSquare, UniformSphere) {
  Rng rng(3, 0);
  SphereHistogram h(20, 40);
  for (int i = 0; i < kSamples; ++i) {
    const Vec3 d = uniformSphere(rng.uniform(), rng.uniform());
    h.add(d.x, d.y, d.z);
  }
  const auto pdf = [](double, double) { return static_cast<double>(kUniformSpherePdf); };
  const auto r = chiSquareTest(h.counts, h.expected(pdf, kSamples));
  EXPECT_TRUE(r.accepted()) << r.describe();
}

// Free flights of delta and ratio tracking against sigma exp(-sigma t): 64 cells over
// five mean free paths, and one cell for the exp(-5) = 0.7 % beyond.
TEST(SamplingChiSquare, ExponentialFreeFlight) {
  for (double sigma : {0.7, 12.0}) {
    Rng rng(4, static_cast<uint64_t>(sigma * 10));
    LineHistogram h(0.0, 5.0 / sigma, 64);
    for (int i = 0; i < kSamples; ++i)
      h.add(sampleExponential(rng.uniform(), static_cast<float>(sigma)));
    const auto pdf = [&](double t) { return sigma * std::exp(-sigma * t); };
    const auto r = chiSquareTest(h.counts, h.expected(pdf, kSamples));
    EXPECT_TRUE(r.accepted()) << "sigma " << sigma << ": " << r.describe();
  }
}

// Equiangular samples against 1 / (h^2 + (t - delta)^2), normalised by quadrature (not by
// the sampler's closed form), for a light beside the segment and one beyond its end; and
// the sampler's own pdf against the same density.
TEST(SamplingChiSquare, Equiangular) {
  struct Case {
    double delta, h, a, b;
  };
  for (const Case c : {Case{1.0, 0.05, 0.0, 3.0}, Case{-2.0, 0.7, 0.5, 4.0}}) {
    const EquiangularSampler eq(static_cast<float>(c.delta), static_cast<float>(c.h),
                                static_cast<float>(c.a), static_cast<float>(c.b));
    ASSERT_TRUE(eq.valid());
    const auto shape = [&](double t) { return 1.0 / (c.h * c.h + (t - c.delta) * (t - c.delta)); };
    const double norm = test::adaptiveSimpson(shape, c.a, c.b, 1e-10, 30);
    const auto pdf = [&](double t) { return shape(t) / norm; };
    for (double t : {c.a, 0.5 * (c.a + c.b), c.b, c.delta})
      if (t >= c.a && t <= c.b) {
        EXPECT_NEAR(eq.pdf(static_cast<float>(t)), pdf(t), 1e-5 * pdf(t));
      }
    Rng rng(5, static_cast<uint64_t>(c.b));
    LineHistogram h(c.a, c.b, 64);
    for (int i = 0; i < kSamples; ++i) h.add(eq.sample(rng.uniform()));
    const auto r = chiSquareTest(h.counts, h.expected(pdf, kSamples));
    EXPECT_TRUE(r.accepted()) << "delta " << c.delta << ": " << r.describe();
  }
}

}  // namespace
}  // namespace lvox
