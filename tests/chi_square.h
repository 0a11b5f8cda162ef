#pragma once
// Pearson chi-square goodness-of-fit tests of samplers, as pbrt and Mitsuba test theirs:
// histogram many samples into cells, integrate the pdf the sampler claims over each cell
// to get the expected counts, pool cells whose expected count is below 5 (the chi-square
// approximation needs it), and turn the statistic into a p-value with the regularised
// incomplete gamma function. A test rejects at significance kChiSquareAlpha, 0.01 divided
// by the number of chi-square tests in the suite (Bonferroni), with fixed seeds, so the
// suite is deterministic and a correct sampler fails it with probability below 1 %.
// Method and thresholds: docs/hardening.md.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <numbers>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

namespace lvox::test {

// Chi-square tests in tests/core, tests/volume, tests/world, tests/pointcloud and tests/render
// together (update when adding one).
inline constexpr int kChiSquareTests = 24;
inline constexpr double kChiSquareAlpha = 0.01 / kChiSquareTests;

// Regularised upper incomplete gamma Q(a, x) = Gamma(a, x) / Gamma(a): series below
// x = a + 1, Lentz's continued fraction above (Numerical Recipes, 3rd ed., 6.2).
inline double gammaQ(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double logPrefix = a * std::log(x) - x - std::lgamma(a);
  constexpr double kEps = 1e-15;
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 100000 && std::abs(term) > std::abs(sum) * kEps; ++n) {
      term *= x / (a + n);
      sum += term;
    }
    return 1.0 - sum * std::exp(logPrefix);
  }
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kEps) break;
  }
  return std::exp(logPrefix) * h;
}

// p-value of a chi-square statistic with `dof` degrees of freedom: P(X >= statistic).
inline double chiSquarePValue(double statistic, int dof) {
  return gammaQ(0.5 * dof, 0.5 * statistic);
}

struct ChiSquareResult {
  double statistic = 0.0;
  int dof = 0;
  double pValue = 0.0;
  std::string failure;  // non-empty: samples where the pdf is zero, or nothing to test
  bool accepted(double alpha = kChiSquareAlpha) const { return failure.empty() && pValue >= alpha; }
  std::string describe() const {
    std::ostringstream s;
    s << "chi2 = " << statistic << ", dof = " << dof << ", p = " << pValue;
    if (!failure.empty()) s << " (" << failure << ")";
    return s.str();
  }
};

// Pearson's test on observed and expected counts per cell (pbrt-v3's pooling: cells in
// increasing order of expected count join one pooled cell until it reaches `minExpected`).
inline ChiSquareResult chiSquareTest(const std::vector<double>& observed,
                                     const std::vector<double>& expected,
                                     double minExpected = 5.0) {
  ChiSquareResult r;
  const double total = std::accumulate(observed.begin(), observed.end(), 0.0);
  std::vector<size_t> order(expected.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return expected[a] < expected[b]; });
  double pooledObserved = 0.0, pooledExpected = 0.0;
  int cells = 0;
  for (size_t i : order) {
    if (expected[i] <= 0.0) {
      // The sampler must not land where its pdf integrates to zero (a few samples on a
      // cell border are allowed for rounding, as in pbrt).
      if (observed[i] > 1e-5 * total) r.failure = "samples where the pdf integrates to zero";
    } else if (expected[i] < minExpected ||
               (pooledExpected > 0.0 && pooledExpected < minExpected)) {
      pooledObserved += observed[i];
      pooledExpected += expected[i];
    } else {
      const double d = observed[i] - expected[i];
      r.statistic += d * d / expected[i];
      ++cells;
    }
  }
  if (pooledExpected > 0.0) {
    const double d = pooledObserved - pooledExpected;
    r.statistic += d * d / pooledExpected;
    ++cells;
  }
  r.dof = cells - 1;
  if (r.dof < 1) {
    r.failure = "fewer than two cells to compare";
    return r;
  }
  r.pValue = chiSquarePValue(r.statistic, r.dof);
  // LVOX_CHI2_PRINT=1 prints every statistic (how docs/hardening.md's table was made).
  if (std::getenv("LVOX_CHI2_PRINT"))
    std::fprintf(stderr, "chi-square: %s\n", r.describe().c_str());
  return r;
}

// Adaptive Simpson quadrature of f on [a, b] to absolute tolerance eps.
inline double adaptiveSimpson(const std::function<double(double)>& f, double a, double b,
                              double eps, int depth = 16) {
  struct Rec {
    const std::function<double(double)>& f;
    double run(double a, double b, double fa, double fm, double fb, double whole, double eps,
               int depth) const {
      const double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
      const double flm = f(lm), frm = f(rm);
      const double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
      const double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
      const double delta = left + right - whole;
      if (depth <= 0 || std::abs(delta) <= 15.0 * eps) return left + right + delta / 15.0;
      return run(a, m, fa, flm, fm, left, 0.5 * eps, depth - 1) +
             run(m, b, fm, frm, fb, right, 0.5 * eps, depth - 1);
    }
  };
  const double fa = f(a), fm = f(0.5 * (a + b)), fb = f(b);
  const Rec rec{f};
  return rec.run(a, b, fa, fm, fb, (b - a) / 6.0 * (fa + 4.0 * fm + fb), eps, depth);
}

// Integral of f(x, y) over [x0, x1] x [y0, y1] by nested adaptive Simpson.
inline double adaptiveSimpson2D(const std::function<double(double, double)>& f, double x0,
                                double x1, double y0, double y1, double eps, int depth = 12) {
  const auto inner = [&](double x) {
    return adaptiveSimpson([&](double y) { return f(x, y); }, y0, y1, eps, depth);
  };
  return adaptiveSimpson(inner, x0, x1, eps * (y1 - y0), depth);
}

// Directions binned in cos(theta) in [-1, 1] and phi in [0, 2 pi): equal solid angle per
// cell, so a uniform sampler fills every cell alike.
struct SphereHistogram {
  int cosBins, phiBins;
  std::vector<double> counts;

  SphereHistogram(int cosBins_, int phiBins_)
      : cosBins(cosBins_),
        phiBins(phiBins_),
        counts(static_cast<size_t>(cosBins_) * static_cast<size_t>(phiBins_), 0.0) {}

  void add(double x, double y, double z) {
    const double cosTheta = std::clamp(z, -1.0, 1.0);
    double phi = std::atan2(y, x);
    if (phi < 0.0) phi += 2.0 * std::numbers::pi;
    const int i = std::clamp(static_cast<int>((cosTheta + 1.0) * 0.5 * cosBins), 0, cosBins - 1);
    const int j =
        std::clamp(static_cast<int>(phi / (2.0 * std::numbers::pi) * phiBins), 0, phiBins - 1);
    counts[static_cast<size_t>(i) * static_cast<size_t>(phiBins) + static_cast<size_t>(j)] += 1.0;
  }

  // Expected counts of `samples` directions drawn with the solid-angle pdf(cosTheta, phi).
  // Each cell is first split `split` x `split` times: adaptive quadrature only refines
  // where its first points see something, so a pdf with small support inside a cell (an
  // emitter's corner) needs a finer start.
  std::vector<double> expected(const std::function<double(double, double)>& pdf, double samples,
                               double eps = 1e-7, int split = 1) const {
    std::vector<double> out(counts.size());
    const double dc = 2.0 / (cosBins * split), dp = 2.0 * std::numbers::pi / (phiBins * split);
    for (int i = 0; i < cosBins * split; ++i)
      for (int j = 0; j < phiBins * split; ++j)
        out[static_cast<size_t>(i / split) * static_cast<size_t>(phiBins) +
            static_cast<size_t>(j / split)] +=
            samples * adaptiveSimpson2D(pdf, -1.0 + i * dc, -1.0 + (i + 1) * dc, j * dp,
                                        (j + 1) * dp, eps / (split * split));
    return out;
  }
};

// One-dimensional histogram on [lo, hi) in `bins` cells, plus one overflow cell for
// samples at or beyond hi (for unbounded samplers; its expected count is what the pdf
// leaves outside [lo, hi)).
struct LineHistogram {
  double lo, hi;
  int bins;
  std::vector<double> counts;

  LineHistogram(double lo_, double hi_, int bins_)
      : lo(lo_), hi(hi_), bins(bins_), counts(static_cast<size_t>(bins_) + 1, 0.0) {}

  void add(double t) {
    if (!(t >= lo)) {
      counts[0] += 1.0;  // below the range: lands in a cell whose check will fail
      return;
    }
    const int i =
        t >= hi ? bins : std::min(bins - 1, static_cast<int>((t - lo) / (hi - lo) * bins));
    counts[static_cast<size_t>(i)] += 1.0;
  }

  std::vector<double> expected(const std::function<double(double)>& pdf, double samples,
                               double eps = 1e-9) const {
    std::vector<double> out(counts.size());
    double inside = 0.0;
    for (int i = 0; i < bins; ++i) {
      const double a = lo + (hi - lo) * i / bins, b = lo + (hi - lo) * (i + 1) / bins;
      const double p = adaptiveSimpson(pdf, a, b, eps);
      out[static_cast<size_t>(i)] = samples * p;
      inside += p;
    }
    out[static_cast<size_t>(bins)] = samples * std::max(0.0, 1.0 - inside);
    return out;
  }
};

}  // namespace lvox::test
