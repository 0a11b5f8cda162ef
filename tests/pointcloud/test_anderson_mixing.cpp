// Anderson mixing of a fixed-point iteration (pointcloud/anderson_mixing.h) on linear maps
// x = b + W x whose fixed point is known, as the interreflection's passes are.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <vector>

#include "pointcloud/anderson_mixing.h"

namespace lvox {
namespace {

// A symmetric W = Q diag(lambda) Q^T with eigenvalues spread over [0.05, rho]: a slow mode
// at rho and faster ones, as an interreflection has. Q: a product of Householder
// reflections of fixed vectors.
struct LinearMap {
  int n;
  std::vector<double> w;  // n x n
  std::vector<double> b;

  LinearMap(int size, double rho) : n(size), w(size * size, 0.0), b(size) {
    std::vector<double> q(size * size, 0.0);
    for (int i = 0; i < n; ++i) q[i * n + i] = 1.0;
    for (int h = 0; h < 3; ++h) {  // Q = H_2 H_1 H_0
      std::vector<double> v(n);
      double norm = 0.0;
      for (int i = 0; i < n; ++i) norm += (v[i] = std::sin(1.7 * (i + 1) * (h + 1)) + 0.3) * v[i];
      for (double& x : v) x /= std::sqrt(norm);
      for (int c = 0; c < n; ++c) {
        double d = 0.0;
        for (int i = 0; i < n; ++i) d += v[i] * q[i * n + c];
        for (int i = 0; i < n; ++i) q[i * n + c] -= 2.0 * v[i] * d;
      }
    }
    for (int k = 0; k < n; ++k) {
      const double lambda = 0.05 + (rho - 0.05) * k / (n - 1);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) w[i * n + j] += q[i * n + k] * lambda * q[j * n + k];
    }
    for (int i = 0; i < n; ++i) b[i] = 1.0 + 0.5 * std::cos(0.9 * i);
  }
  std::vector<float> apply(const std::vector<float>& x) const {
    std::vector<float> g(n);
    for (int i = 0; i < n; ++i) {
      double s = b[i];
      for (int j = 0; j < n; ++j) s += w[i * n + j] * x[j];
      g[i] = static_cast<float>(s);
    }
    return g;
  }
  // |x - x*|_inf with x* from 4000 plain iterations in double.
  double error(const std::vector<float>& x) const {
    std::vector<double> fixed(n, 0.0), next(n);
    for (int it = 0; it < 4000; ++it) {
      for (int i = 0; i < n; ++i) {
        double s = b[i];
        for (int j = 0; j < n; ++j) s += w[i * n + j] * fixed[j];
        next[i] = s;
      }
      fixed.swap(next);
    }
    double e = 0.0;
    for (int i = 0; i < n; ++i) e = std::max(e, std::abs(x[i] - fixed[i]) / std::abs(fixed[i]));
    return e;
  }
};

// Plain passes shrink the error by rho = 0.9 per pass: 20 passes leave 0.9^20 = 12 % of it.
// Mixing over 5 past passes reaches 1e-3 in the same 20 (measured 3.7e-4: a Krylov method,
// the slowest modes go first); depth 1 (measured 0.015) is already ten times closer.
TEST(AndersonMixing, ConvergesFarFasterThanPlainPassesOnASlowLinearMap) {
  const LinearMap map(40, 0.9);
  std::vector<float> plain(40, 0.0f);
  for (int it = 0; it < 20; ++it) plain = map.apply(plain);
  const double plainError = map.error(plain);
  EXPECT_GT(plainError, 0.02);
  for (int depth : {1, 5}) {
    AndersonMixing mixing(40, depth);
    std::vector<float> x(40, 0.0f);
    for (int it = 0; it < 20; ++it) mixing.mix(x, map.apply(x));
    const double mixedError = map.error(x);
    std::printf("depth %d: %.3g (plain %.3g)\n", depth, mixedError, plainError);
    EXPECT_LT(mixedError, depth == 5 ? 1e-3 : 0.1 * plainError) << depth;
  }
}

// The first mix has no history and returns G(x): a plain pass; a mix that meets dependent
// differences (here: a map that has converged, every difference zero) drops them and
// stays plain rather than dividing by zero.
TEST(AndersonMixing, TheFirstMixAndDependentDifferencesArePlain) {
  AndersonMixing mixing(3, 3);
  std::vector<float> x{1.0f, 2.0f, 3.0f};
  const std::vector<float> g{2.0f, 2.0f, 2.0f};
  mixing.mix(x, g);
  EXPECT_EQ(x, g);
  EXPECT_EQ(mixing.used(), 0);
  for (int it = 0; it < 3; ++it) {
    // G constant: x = g already. The second mix has one difference, f's first change, and
    // a zero residual to fit (its weight is 0); from the third on the differences vanish.
    mixing.mix(x, g);
    EXPECT_EQ(x, g);
    if (it > 0) {
      EXPECT_EQ(mixing.used(), 0);
    }
  }
}

// The mix is the same whatever the thread count: fixed blocks summed in order. Over a
// vector of several blocks, on one thread and on all of them: bit-identical results.
TEST(AndersonMixing, IsDeterministic) {
  const size_t n = 50000;
  auto run = [&] {
    AndersonMixing mixing(n, 3);
    std::vector<float> x(n, 0.0f), g(n);
    for (int it = 0; it < 6; ++it) {
      for (size_t i = 0; i < n; ++i)
        g[i] = 0.8f * x[(i + 1) % n] + 1.0f + 1e-3f * static_cast<float>(i % 13);
      mixing.mix(x, g);
    }
    return x;
  };
  const std::vector<float> all = run();
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  EXPECT_EQ(run(), all);
}

}  // namespace
}  // namespace lvox
