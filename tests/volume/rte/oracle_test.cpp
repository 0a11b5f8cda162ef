// Every method against the per-ray oracles of oracles.md 2.1-2.3 and 2.7.
// Tolerances for fixed-step methods come from the method's order: asymptotically
// e(h) = C h^p, so e(h) ~= (L_h - L_{h/2}) 2^p / (2^p - 1) (Richardson). We assert that the
// true error is below twice that estimate (the factor 2 covers the O(h^{p+1}) remainder at
// these steps) plus 1e-13 of rounding. Adaptive methods run at tol = 1e-10: their global
// error is bounded by ~tol times the number of steps and the problem's growth factor (<= 1
// here, the ODE is contractive), far below the asserted 1e-7.
#include <gtest/gtest.h>

#include <cmath>

#include "volume/rte/rte_oracles.h"
#include "volume/rte/solve.h"

namespace lvox::rte {
namespace {

using namespace test;

constexpr Method kFixed[] = {Method::kEuler,       Method::kRk2,           Method::kRk4,
                             Method::kAb4,         Method::kBackwardEuler, Method::kTrapezoid,
                             Method::kTrapezoidPc, Method::kRectangle,     Method::kSimpson};
constexpr Method kAdaptive[] = {
    Method::kRk12,   Method::kBs23,     Method::kRkf45,           Method::kCashKarp,
    Method::kDopri5, Method::kVerner56, Method::kAdaptiveSimpson, Method::kGaussKronrod};

template <class P>
void checkFixed(const P& p, double d, double lbg, double exact, double step) {
  for (Method m : kFixed) {
    SolveSettings<double> s;
    s.step = step;
    s.tolerance = 1e-13;  // trapezoid-pc corrector
    const double coarse = solve(m, p, 0.0, d, C3(lbg), s).radiance[0];
    s.step = step / 2;
    const double fine = solve(m, p, 0.0, d, C3(lbg), s).radiance[0];
    const double pow2 = std::pow(2.0, methodOrder(m));
    const double richardson = std::abs(coarse - fine) * pow2 / (pow2 - 1);
    EXPECT_LE(std::abs(coarse - exact), 2 * richardson + 1e-13) << methodName(m);
    EXPECT_LT(std::abs(fine - exact), std::abs(coarse - exact) + 1e-14) << methodName(m);
    // And the step is fine enough that the answer is useful at all (order 1: 10%).
    EXPECT_LT(std::abs(coarse - exact), (methodOrder(m) == 1 ? 0.1 : 0.01) * exact)
        << methodName(m);
  }
}

template <class P>
void checkAdaptive(const P& p, double d, double lbg, double exact) {
  for (Method m : kAdaptive) {
    SolveSettings<double> s;
    s.step = 0.1;
    // The nested Simpson/trapezoid estimate is of the trapezoid's O(h^3) local error, so it
    // needs h ~ sqrt(tol): tol = 1e-8 is as demanding as 1e-10 for the others.
    s.tolerance = m == Method::kAdaptiveSimpson ? 1e-8 : 1e-10;
    s.minStep = 1e-9;
    s.maxEvaluations = 1000000;
    const auto r = solve(m, p, 0.0, d, C3(lbg), s);
    EXPECT_NEAR(r.radiance[0], exact, 1e-7) << methodName(m);
    EXPECT_FALSE(r.counts.capped) << methodName(m);
  }
}

template <class P>
void checkMonteCarlo(const P& p, double d, double lbg, double exact) {
  // 64 seeds: the mean must lie within 4 standard errors (plus the O(h^2) trapezoid bias
  // of tau, < 1e-5 relative at h = 0.01) of the oracle.
  SolveSettings<double> s;
  s.step = 0.01;
  double sum = 0, sum2 = 0;
  const int n = 64;
  for (int seed = 0; seed < n; ++seed) {
    s.seed = static_cast<uint64_t>(seed);
    const double v = solve(Method::kMonteCarlo, p, 0.0, d, C3(lbg), s).radiance[0];
    sum += v, sum2 += v * v;
  }
  const double mean = sum / n, sd = std::sqrt(std::max(0.0, sum2 / n - mean * mean));
  EXPECT_NEAR(mean, exact, 4 * sd / std::sqrt(double(n)) + 1e-5 * exact);
  EXPECT_LT(sd, 1e-3 * exact);  // jittered 1-D sampling: tiny noise at 200+ strata
}

TEST(RteOracle, SlabReferenceValue) {
  const Slab slab;
  const double exact = slab.exact(2.0, 0.5);
  EXPECT_NEAR(exact, 0.0774395173508268509, 1e-16);
  checkFixed(slab, 2.0, 0.5, exact, 0.05);
  checkAdaptive(slab, 2.0, 0.5, exact);
  checkMonteCarlo(slab, 2.0, 0.5, exact);
}

TEST(RteOracle, PointLightOracleItself) {
  EXPECT_NEAR(pointLightOracle(PointLight{}, 5.0), 0.268894006206365554, 1e-14);
  const PointLight close{-1, 0.05, 0.02, 2, 2, 1};
  EXPECT_NEAR(pointLightOracle(close, 3.0), 0.00374350657493872162, 1e-16);
  const PointLight far{1, 3, 0, 0.1, 0.05, 3};
  EXPECT_NEAR(pointLightOracle(far, 10.0), 0.00324340116961524863, 1e-16);
}

TEST(RteOracle, PointLight) {
  const PointLight p;
  const double exact = 0.268894006206365554;
  checkFixed(p, 5.0, 0.0, exact, 0.05);
  checkAdaptive(p, 5.0, 0.0, exact);
  checkMonteCarlo(p, 5.0, 0.0, exact);
}

TEST(RteOracle, GaussianOpticalDepth) {
  const GaussianBlob blob;
  EXPECT_NEAR(blob.tau(4.0), 1.70876103680006489, 1e-14);
  const double exact = std::exp(-1.70876103680006489);
  checkFixed(blob, 4.0, 1.0, exact, 0.05);
  checkAdaptive(blob, 4.0, 1.0, exact);
  for (Method m : kAllMethods) {
    SolveSettings<double> s;
    s.step = 0.01;
    s.tolerance = 1e-7;
    const auto r = solveTransmittance(m, blob, 0.0, 4.0, s);
    // Order-1 methods at h = 0.01: error ~ h tau'' / 2 ~ 3e-3; the others are far below 1e-4.
    EXPECT_NEAR(r.transmittance[0], exact, methodOrder(m) == 1 ? 5e-3 : 1e-4) << methodName(m);
    EXPECT_FALSE(r.counts.capped) << methodName(m);
    EXPECT_NEAR(r.opticalDepth[0], -std::log(r.transmittance[0]), 1e-12) << methodName(m);
    EXPECT_EQ(r.radiance[0], 0.0);
  }
}

TEST(RteOracle, EmissionAbsorption) {
  const EmissionAbsorption ea;
  const double exact = 0.799006475027685711;
  EXPECT_NEAR(ea.exact(3.0, 0.3), exact, 1e-15);
  checkFixed(ea, 3.0, 0.3, exact, 0.02);
  checkAdaptive(ea, 3.0, 0.3, exact);
  checkMonteCarlo(ea, 3.0, 0.3, exact);
}

TEST(RteOracle, FloatSmoke) {
  // The renderer's precision: RK4 at h = 0.05 on the slab, error ~1e-7 from truncation plus
  // float rounding over 40 steps (~40 * 6e-8 relative).
  const struct {
    MediumSample<float> eval(float t) const {
      const Sample s = Slab{}.eval(double(t));
      return {Channels<float>(float(s.sigmaT[0])), Channels<float>(float(s.source[0]))};
    }
  } p;
  SolveSettings<float> s;
  s.step = 0.05f;
  for (Method m : {Method::kRk4, Method::kDopri5, Method::kSimpson, Method::kGaussKronrod}) {
    const auto r = solve(m, p, 0.0f, 2.0f, Channels<float>(0.5f), s);
    EXPECT_NEAR(r.radiance[0], 0.0774395173508268509, 5e-6) << methodName(m);
  }
}

}  // namespace
}  // namespace lvox::rte
