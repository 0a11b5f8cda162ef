// G7-K15 exactness (oracles.md 3.2): K15 integrates x^k exactly on [-1, 1] through degree
// 23 (22 by construction, 23 by symmetry) and first fails at 24; G7 through 13, first
// failing at 14. The partial-integral matrix used for the optical depth at the nodes is
// exact for the degree-14 interpolant.
#include <gtest/gtest.h>

#include <cmath>

#include "volume/rte/quadrature.h"

namespace lvox::rte {
namespace {

double monomialIntegral(int k, double a, double b) {
  return (std::pow(b, k + 1) - std::pow(a, k + 1)) / (k + 1);
}

int firstFailingDegree(const std::array<double, 15>& w) {
  const GaussKronrod15& gk = gaussKronrod15();
  for (int k = 0; k < 40; ++k) {
    double sum = 0;
    for (int i = 0; i < 15; ++i) sum += w[i] * std::pow(gk.nodes[i], k);
    if (std::abs(sum - monomialIntegral(k, -1, 1)) > 1e-14) return k;
  }
  return -1;
}

TEST(RteGaussKronrod, ExactnessDegrees) {
  const GaussKronrod15& gk = gaussKronrod15();
  EXPECT_EQ(firstFailingDegree(gk.kronrodWeights), 24);
  EXPECT_EQ(firstFailingDegree(gk.gaussWeights), 14);
}

TEST(RteGaussKronrod, PartialIntegralsExactForDegree14) {
  const GaussKronrod15& gk = gaussKronrod15();
  for (int k : {0, 1, 7, 14}) {
    for (int i = 0; i < 15; ++i) {
      double sum = 0;
      for (int j = 0; j < 15; ++j) sum += gk.partial[i][j] * std::pow(gk.nodes[j], k);
      EXPECT_NEAR(sum, monomialIntegral(k, -1, gk.nodes[i]), 1e-12) << "k " << k << " i " << i;
    }
  }
}

}  // namespace
}  // namespace lvox::rte
