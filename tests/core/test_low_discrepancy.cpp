// The Owen-scrambled (0,2)-sequence of src/core/low_discrepancy.h: the net property of its
// power-of-two prefixes, uniform points over scrambles, and the error it buys on an edge.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "src/core/low_discrepancy.h"
#include "src/core/rng.h"

namespace lvox {
namespace {

TEST(LowDiscrepancy, ReverseBitsAndTheUnscrambledSequence) {
  EXPECT_EQ(reverseBits(1u), 0x80000000u);
  EXPECT_EQ(reverseBits(0x0000000fu), 0xf0000000u);
  EXPECT_EQ(reverseBits(0x12345678u), 0x1e6a2c48u);
  // Sobol's first points in index order (not Gray-code order): dimension 0 is the radical
  // inverse of the index, dimension 1 its product with the Pascal matrix mod 2.
  const double expected[5][2] = {{0, 0}, {0.5, 0.5}, {0.25, 0.75}, {0.75, 0.25}, {0.125, 0.625}};
  for (uint32_t i = 0; i < 5; ++i) {
    EXPECT_EQ(sobolDimension0(i) * 0x1p-32, expected[i][0]) << i;
    EXPECT_EQ(sobolDimension1(i) * 0x1p-32, expected[i][1]) << i;
  }
}

// Every prefix of 2^m points, for every scramble, has exactly one point in each
// elementary interval 2^-a x 2^-(m-a): the property the pixel samples rely on.
TEST(LowDiscrepancy, PowerOfTwoPrefixesAreNets) {
  Rng rng(7, 0);
  for (int scramble = 0; scramble < 20; ++scramble) {
    const uint32_t seedU = rng.next(), seedV = rng.next();
    for (int m = 0; m <= 10; ++m) {
      const uint32_t n = 1u << m;
      for (int a = 0; a <= m; ++a) {
        std::vector<int> count(n, 0);
        for (uint32_t i = 0; i < n; ++i) {
          const UnitPoint2 p = scrambledSobol2(i, seedU, seedV);
          const auto cu = static_cast<uint32_t>(std::ldexp(p.u, a));
          const auto cv = static_cast<uint32_t>(std::ldexp(p.v, m - a));
          ++count[(cu << (m - a)) | cv];
        }
        for (uint32_t c = 0; c < n; ++c)
          ASSERT_EQ(count[c], 1) << "scramble " << scramble << ", m " << m << ", a " << a;
      }
    }
  }
}

// Over scrambles, each point is uniform on the square: 16 x 16 cells hold 40,000
// scrambles' point i within 5 standard deviations (Poisson: 156 +- 62), for several i.
TEST(LowDiscrepancy, EachPointIsUniformOverScrambles) {
  constexpr int kScrambles = 40000, kCells = 16;
  for (uint32_t index : {0u, 1u, 3u, 6u, 1000u}) {
    Rng rng(11, index);
    std::vector<int> count(kCells * kCells, 0);
    for (int s = 0; s < kScrambles; ++s) {
      const UnitPoint2 p = scrambledSobol2(index, rng.next(), rng.next());
      ASSERT_GE(p.u, 0.0f);
      ASSERT_LT(p.u, 1.0f);
      ASSERT_GE(p.v, 0.0f);
      ASSERT_LT(p.v, 1.0f);
      ++count[static_cast<int>(p.u * kCells) * kCells + static_cast<int>(p.v * kCells)];
    }
    const double expected = static_cast<double>(kScrambles) / (kCells * kCells);
    double chi2 = 0.0;
    for (int c : count) chi2 += (c - expected) * (c - expected) / expected;
    // 255 degrees of freedom: mean 255, sd 22.6; 400 is p < 1e-8.
    EXPECT_LT(chi2, 400.0) << "point " << index;
  }
}

// The RMS error of the area under an inclined edge, over 4,000 scrambles, for N = 4 to
// 1024 points. Independent points fall as N^-0.5; Owen-scrambled nets as about N^-0.75
// on such a discontinuity (Owen 1997; a log factor makes it a little slower). The slope
// of a least-squares fit in log-log must be below -0.65, and at N = 4 the error at
// most 0.75 of independent points'.
TEST(LowDiscrepancy, EdgeErrorFallsFasterThanWithIndependentPoints) {
  const auto inside = [](float u, float v) { return v < 0.2f + 0.55f * u; };
  constexpr double kArea = 0.2 + 0.55 / 2.0;
  constexpr int kScrambles = 4000;
  std::vector<double> logN, logError;
  double independentAt4 = 0.0, scrambledAt4 = 0.0;
  for (uint32_t n = 4; n <= 1024; n *= 4) {
    Rng rng(3, n);
    double sum2 = 0.0, independent2 = 0.0;
    for (int s = 0; s < kScrambles; ++s) {
      const uint32_t seedU = rng.next(), seedV = rng.next();
      int hits = 0, independentHits = 0;
      for (uint32_t i = 0; i < n; ++i) {
        const UnitPoint2 p = scrambledSobol2(i, seedU, seedV);
        hits += inside(p.u, p.v);
        independentHits += inside(rng.uniform(), rng.uniform());
      }
      const double e = hits / static_cast<double>(n) - kArea;
      const double ei = independentHits / static_cast<double>(n) - kArea;
      sum2 += e * e;
      independent2 += ei * ei;
    }
    const double rms = std::sqrt(sum2 / kScrambles);
    if (n == 4) {
      scrambledAt4 = rms;
      independentAt4 = std::sqrt(independent2 / kScrambles);
    }
    logN.push_back(std::log(n));
    logError.push_back(std::log(rms));
  }
  const double k = static_cast<double>(logN.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < logN.size(); ++i) {
    sx += logN[i];
    sy += logError[i];
    sxx += logN[i] * logN[i];
    sxy += logN[i] * logError[i];
  }
  const double slope = (k * sxy - sx * sy) / (k * sxx - sx * sx);
  EXPECT_LT(slope, -0.65);
  EXPECT_GT(slope, -1.0);  // faster would mean the points are not random at all
  EXPECT_LT(scrambledAt4, 0.75 * independentAt4);
}

}  // namespace
}  // namespace lvox
