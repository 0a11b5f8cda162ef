#include "pointcloud/anderson_mixing.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "src/core/check.h"

namespace lvox {
namespace {

constexpr size_t kBlock = 8192;

// Solves A y = r for a symmetric positive definite A (n x n, row-major) by Cholesky; false
// when a pivot falls below `relativePivot` of its diagonal (the columns are nearly
// dependent: their combination would amplify rounding).
bool choleskySolve(std::vector<double> a, std::vector<double>& y, int n, double relativePivot) {
  for (int j = 0; j < n; ++j) {
    double d = a[j * n + j];
    for (int k = 0; k < j; ++k) d -= a[j * n + k] * a[j * n + k];
    if (!(d > relativePivot * a[j * n + j])) return false;
    const double l = std::sqrt(d);
    a[j * n + j] = l;
    for (int i = j + 1; i < n; ++i) {
      double s = a[i * n + j];
      for (int k = 0; k < j; ++k) s -= a[i * n + k] * a[j * n + k];
      a[i * n + j] = s / l;
    }
  }
  for (int i = 0; i < n; ++i) {  // L z = r
    double s = y[i];
    for (int k = 0; k < i; ++k) s -= a[i * n + k] * y[k];
    y[i] = s / a[i * n + i];
  }
  for (int i = n - 1; i >= 0; --i) {  // L^T y = z
    double s = y[i];
    for (int k = i + 1; k < n; ++k) s -= a[k * n + i] * y[k];
    y[i] = s / a[i * n + i];
  }
  return true;
}

}  // namespace

AndersonMixing::AndersonMixing(size_t size, int depth)
    : size_(size),
      depth_(std::max(depth, 1)),
      previousF_(size),
      previousG_(size),
      deltaF_(static_cast<size_t>(depth_), std::vector<float>(size)),
      deltaG_(static_cast<size_t>(depth_), std::vector<float>(size)),
      gram_(static_cast<size_t>(depth_ * depth_), 0.0) {}

size_t AndersonMixing::bytesFor(size_t size, int depth) {
  return (2 + 2 * static_cast<size_t>(std::max(depth, 1))) * size * sizeof(float);
}

void AndersonMixing::mix(std::span<float> x, std::span<const float> g) {
  LVOX_CHECK(x.size() == size_ && g.size() == size_, "Anderson mixing: vector of the wrong size");
  const int slot = (newest_ + 1) % depth_;
  const bool grows = havePrevious_;
  auto column = [&](int j) { return (slot - j + depth_) % depth_; };  // j = 0: the newest
  const int n = grows ? std::min(stored_ + 1, depth_) : 0;
  // One sweep: the residual f = g - x, the newest differences of f and g, and the dot
  // products the least squares needs: <dF_j, f> and the newest column's <dF_0, dF_j> (the
  // older columns' products are kept), summed by fixed blocks in block order.
  const size_t blocks = (size_ + kBlock - 1) / kBlock;
  const size_t stride = 2 * static_cast<size_t>(n);
  std::vector<double> partial(blocks * stride, 0.0);
  std::vector<const float*> columnF(static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) columnF[j] = deltaF_[column(j)].data();
  float* newF = deltaF_[slot].data();
  float* newG = deltaG_[slot].data();
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    double* out = partial.data() + b * stride;
    for (size_t i = b * kBlock; i < std::min(size_, (b + 1) * kBlock); ++i) {
      const float f = g[i] - x[i];
      if (grows) {
        newF[i] = f - previousF_[i];
        newG[i] = g[i] - previousG_[i];
        const double newest = newF[i];
        for (int j = 0; j < n; ++j) {
          const double c = columnF[j][i];
          out[j] += c * f;
          out[n + j] += newest * c;
        }
      }
      previousF_[i] = f;
      previousG_[i] = g[i];
    }
  });
  havePrevious_ = true;
  used_ = 0;
  if (!grows) {
    std::copy(g.begin(), g.end(), x.begin());
    return;
  }
  newest_ = slot;
  stored_ = n;
  std::vector<double> rhs(static_cast<size_t>(n), 0.0), newestRow(static_cast<size_t>(n), 0.0);
  for (size_t b = 0; b < blocks; ++b)
    for (int j = 0; j < n; ++j) {
      rhs[j] += partial[b * stride + j];
      newestRow[j] += partial[b * stride + n + j];
    }
  // The Gram matrix of the columns, by slot: the newest slot's row and column are new.
  for (int j = 0; j < n; ++j) {
    gram_[slot * depth_ + column(j)] = newestRow[j];
    gram_[column(j) * depth_ + slot] = newestRow[j];
  }
  // min |f - sum_j gamma_j dF_j| over the newest `k` columns; the oldest go first where
  // they are nearly dependent on the rest.
  for (int k = n; k > 0; --k) {
    std::vector<double> a(static_cast<size_t>(k * k));
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) a[i * k + j] = gram_[column(i) * depth_ + column(j)];
    std::vector<double> gamma(rhs.begin(), rhs.begin() + k);
    if (!choleskySolve(a, gamma, k, 1e-10)) continue;
    // x_{k+1} = g - sum_j gamma_j dG_j
    std::vector<const float*> columnG(static_cast<size_t>(k));
    for (int j = 0; j < k; ++j) columnG[j] = deltaG_[column(j)].data();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, size_, kBlock), [&](const auto& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) {
        double v = g[i];
        for (int j = 0; j < k; ++j) v -= gamma[j] * columnG[j][i];
        x[i] = static_cast<float>(v);
      }
    });
    used_ = k;
    return;
  }
  std::copy(g.begin(), g.end(), x.begin());
}

}  // namespace lvox
