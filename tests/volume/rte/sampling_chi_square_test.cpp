// The changes of variable of volume/rte/change_of_variable.h ("distance" and
// "equiangular" sampling of the RTE solvers and auto_solver's panels) are inverse CDFs:
// s uniform between toS(a) and toS(b) must give t with the truncated exponential and the
// inverse-square (Cauchy) densities. Chi-square tests against those densities, written
// out here and normalised by quadrature (method: tests/chi_square.h), and dt/ds against
// the density: 1 / (pdf(t) (s_b - s_a)).
#include <gtest/gtest.h>

#include <cmath>

#include "chi_square.h"
#include "src/core/rng.h"
#include "volume/rte/change_of_variable.h"

namespace lvox::rte {
namespace {

constexpr int kSamples = 1000000;

void checkMap(const VariableChange<double>& map, double a, double b,
              const std::function<double(double)>& shape, uint64_t seed) {
  const double norm = test::adaptiveSimpson(shape, a, b, 1e-12, 30);
  const auto pdf = [&](double t) { return shape(t) / norm; };
  const double sa = map.toS(a), sb = map.toS(b);
  for (double t : {a, 0.3 * a + 0.7 * b, b}) {
    const double s = map.toS(t);
    EXPECT_NEAR(map.toT(s), t, 1e-9 * (1.0 + std::abs(t)));
    EXPECT_NEAR(1.0 / (map.dtds(s) * (sb - sa)), pdf(t), 1e-7 * pdf(t));
  }
  Rng rng(seed, 0);
  test::LineHistogram h(a, b, 64);
  for (int i = 0; i < kSamples; ++i) h.add(map.toT(sa + rng.uniformDouble() * (sb - sa)));
  const auto r = test::chiSquareTest(h.counts, h.expected(pdf, kSamples));
  EXPECT_TRUE(r.accepted()) << r.describe();
}

TEST(ChangeOfVariableChiSquare, DistanceIsTruncatedExponential) {
  const double t0 = 0.5, sigma = 1.7, b = 3.0;
  const auto map = VariableChange<double>::make(Sampling::kDistance, t0, sigma, 0.0, 1.0);
  ASSERT_EQ(map.kind, Sampling::kDistance);
  checkMap(
      map, t0, b, [&](double t) { return std::exp(-sigma * (t - t0)); }, 30);
}

TEST(ChangeOfVariableChiSquare, EquiangularIsInverseSquare) {
  const double delta = 1.2, h = 0.15;
  const auto map = VariableChange<double>::make(Sampling::kEquiangular, 0.0, 1.0, delta, h);
  ASSERT_EQ(map.kind, Sampling::kEquiangular);
  checkMap(
      map, 0.0, 4.0, [&](double t) { return 1.0 / (h * h + (t - delta) * (t - delta)); }, 31);
}

}  // namespace
}  // namespace lvox::rte
