#include "src/render/adaptive_samples.h"

#include <algorithm>
#include <cmath>

namespace lvox {

double PixelMoments::variance(size_t i) const {
  const auto n = static_cast<double>(count[i]);
  if (n < 2.0) return 0.0;
  const double mean = sum[i] / n;
  return std::max(0.0, (squares[i] - n * mean * mean) / (n - 1.0));
}

namespace {

// sigma_i^(2/3) from the mean variance of pixel i's neighbours (its own excluded).
std::vector<double> neighbourWeights(const PixelMoments& m, int width, int height) {
  std::vector<double> variance(m.sum.size());
  for (size_t i = 0; i < variance.size(); ++i) variance[i] = m.variance(i);
  std::vector<double> weight(variance.size(), 0.0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double sum = 0.0;
      int n = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
          sum += variance[static_cast<size_t>(ny) * width + nx];
          ++n;
        }
      // sigma^(2/3) = variance^(1/3)
      if (n > 0) weight[static_cast<size_t>(y) * width + x] = std::cbrt(sum / n);
    }
  return weight;
}

// The extra samples (beyond lo) of every pixel for a scale c: clamp(c w, lo, hi) - lo.
double extraFor(double c, double w, double lo, double hi) { return std::clamp(c * w, lo, hi) - lo; }

}  // namespace

std::vector<uint32_t> adaptiveExtraSamples(const PixelMoments& moments, int width, int height,
                                           int spp, int meanSpp) {
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  std::vector<uint32_t> extra(pixels, 0);
  if (pixels == 0 || meanSpp <= spp) return extra;
  const std::vector<double> weight = neighbourWeights(moments, width, height);
  const double lo = spp, hi = static_cast<double>(kMaxSamplesPerMean) * meanSpp;
  const double target = static_cast<double>(meanSpp - spp) * static_cast<double>(pixels);
  const double largest = *std::max_element(weight.begin(), weight.end());
  std::vector<double> share(pixels, 0.0);
  double placed = 0.0;
  if (largest > 0.0) {
    // The extra samples grow with c: bisect it between 0 (none) and the c at which every
    // varying pixel is at hi.
    double smallest = largest;
    for (double w : weight)
      if (w > 0.0) smallest = std::min(smallest, w);
    auto total = [&](double c) {
      double t = 0.0;
      for (double w : weight) t += extraFor(c, w, lo, hi);
      return t;
    };
    double below = 0.0, above = hi / smallest;
    if (total(above) > target)
      for (int it = 0; it < 200 && above - below > 1e-12 * above; ++it) {
        const double mid = 0.5 * (below + above);
        (total(mid) < target ? below : above) = mid;
      }
    for (size_t i = 0; i < pixels; ++i) share[i] = extraFor(above, weight[i], lo, hi);
    placed = total(above);
    if (placed > target) {  // the bisection's last step overshoots by a hair
      for (double& x : share) x *= target / placed;
      placed = target;
    }
  }
  // What the varying pixels cannot take (they are all at hi, or nothing varies) goes
  // alike to every pixel below hi (as the budget's mean is, there is room).
  size_t underCap = 0;
  for (double x : share) underCap += x < hi - lo ? 1 : 0;
  const double rest =
      underCap > 0 ? std::max(0.0, target - placed) / static_cast<double>(underCap) : 0.0;
  for (double& x : share)
    if (x < hi - lo) x += rest;
  // In pixel order, each pixel takes the rounded running sum less what came before: the
  // extra samples add up to the target, and each pixel is within one of its share.
  const auto goal = static_cast<uint64_t>(target);
  double running = 0.0;
  uint64_t given = 0;
  for (size_t i = 0; i < pixels; ++i) {
    running += share[i];
    const uint64_t upTo = std::min(goal, static_cast<uint64_t>(std::llround(running)));
    extra[i] = static_cast<uint32_t>(upTo > given ? upTo - given : 0);
    given += extra[i];
  }
  if (given < goal) extra[pixels - 1] += static_cast<uint32_t>(goal - given);
  return extra;
}

}  // namespace lvox
