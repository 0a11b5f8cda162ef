#include "pointcloud/surfel_rays.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "src/core/check.h"
#include "src/core/rng.h"

namespace lvox {
namespace {

uint32_t strideOf(int rays) { return std::bit_ceil(static_cast<uint32_t>(std::max(rays, 1))); }

uint32_t runSize(size_t surfels, size_t run) {
  return static_cast<uint32_t>(std::min(kSurfelRun, surfels - run * kSurfelRun));
}

// The sample deviation of a run's sides' one-ray estimates.
double runDeviation(std::span<const float> values) {
  double mean = 0.0, count = 0.0;
  for (float v : values)
    if (std::isfinite(v)) {
      mean += v;
      count += 1.0;
    }
  if (count < 2.0) return 0.0;
  mean /= count;
  double squares = 0.0;
  for (float v : values)
    if (std::isfinite(v)) squares += (v - mean) * (v - mean);
  return std::sqrt(squares / (count - 1.0));
}

// Each run-side's deviation pooled with those of the kPoolRuns runs on either side of it in
// Morton order (the same side): the root of their mean variance. A run's 16 one-ray
// estimates alone often all miss a small bright spot its sides see, or one of them hits
// it: Neyman by such deviations gave a closed box with a bright patch a noisier cloud than
// even rays (1.34 times the mean squared error); pooled over 17 runs, 0.69 times.
std::vector<double> pooledDeviations(const std::vector<double>& deviation, size_t runs) {
  std::vector<double> pooled(deviation.size());
  for (size_t side = 0; side < 2; ++side) {
    const double* d = deviation.data() + side * runs;
    for (size_t run = 0; run < runs; ++run) {
      const size_t begin = run > kPoolRuns ? run - kPoolRuns : 0;
      const size_t end = std::min(runs, run + kPoolRuns + 1);
      double variance = 0.0;
      for (size_t j = begin; j < end; ++j) variance += d[j] * d[j];
      pooled[side * runs + run] = std::sqrt(variance / static_cast<double>(end - begin));
    }
  }
  return pooled;
}

}  // namespace

SharedStrata SurfelRays::strataOf(size_t surfel, bool front) const {
  const size_t run = surfel / kSurfelRun;
  const uint64_t h =
      splitMix64(seed ^ 0x57a7a5u ^ (static_cast<uint64_t>(run) << 1) ^ (front ? 0u : 1u));
  const auto k = static_cast<uint32_t>(surfel % kSurfelRun);
  return SharedStrata{k * strideOf(raysOf(surfel, front)), static_cast<uint32_t>(h),
                      static_cast<uint32_t>(h >> 32)};
}

uint64_t SurfelRays::totalRays() const {
  uint64_t total = 0;
  const size_t r = runs();
  for (size_t g = 0; g < r; ++g)
    total += runSize(surfels, g) * (static_cast<uint64_t>(perRun[g]) + perRun[r + g]);
  return total;
}

SurfelRays uniformSurfelRays(size_t surfels, int rays, uint64_t seed) {
  SurfelRays plan;
  plan.surfels = surfels;
  plan.seed = seed;
  plan.perRun.assign(2 * plan.runs(), static_cast<uint32_t>(std::max(rays, 1)));
  return plan;
}

std::vector<uint32_t> neymanCounts(std::span<const double> deviation,
                                   std::span<const uint32_t> size, double budget, int lo, int hi) {
  LVOX_CHECK(deviation.size() == size.size() && lo >= 1 && hi >= lo, "neymanCounts: bad groups");
  const size_t groups = deviation.size();
  const auto low = static_cast<double>(lo), high = static_cast<double>(hi);
  double members = 0.0, weighted = 0.0;
  for (size_t g = 0; g < groups; ++g) {
    members += size[g];
    if (deviation[g] > 0.0) weighted += size[g] * deviation[g];
  }
  std::vector<double> share(groups, low);
  if (!(weighted > 0.0)) {  // nothing tells the groups apart
    std::fill(share.begin(), share.end(), members > 0.0 ? budget / members : low);
  } else {
    // The scale at which the clamped shares spend the budget: they grow with it.
    auto spent = [&](double scale) {
      double sum = 0.0;
      for (size_t g = 0; g < groups; ++g)
        sum += size[g] * std::clamp(scale * std::max(deviation[g], 0.0), low, high);
      return sum;
    };
    double below = 0.0, above = budget / weighted;
    for (int it = 0; it < 64 && spent(above) < budget; ++it) above *= 2.0;
    for (int it = 0; it < 64; ++it) {
      const double mid = 0.5 * (below + above);
      (spent(mid) < budget ? below : above) = mid;
    }
    for (size_t g = 0; g < groups; ++g)
      share[g] = std::clamp(above * std::max(deviation[g], 0.0), low, high);
  }
  // Each group in turn takes the count that keeps the running sum nearest its target.
  std::vector<uint32_t> counts(groups);
  double target = 0.0, assigned = 0.0;
  for (size_t g = 0; g < groups; ++g) {
    target += size[g] * share[g];
    const double want = size[g] > 0 ? (target - assigned) / size[g] : share[g];
    const long n = std::clamp(std::lround(want), static_cast<long>(lo), static_cast<long>(hi));
    counts[g] = static_cast<uint32_t>(n);
    assigned += static_cast<double>(size[g]) * static_cast<double>(n);
  }
  return counts;
}

SurfelRays plannedSurfelRays(std::span<const float> sideRadiance, int meanRays, uint64_t seed) {
  LVOX_CHECK(sideRadiance.size() % 2 == 0, "plannedSurfelRays: a value per side");
  const size_t surfels = sideRadiance.size() / 2;
  SurfelRays plan = uniformSurfelRays(surfels, meanRays, seed);
  const size_t runs = plan.runs();
  if (runs == 0) return plan;
  std::vector<double> deviation(2 * runs);
  std::vector<uint32_t> size(2 * runs);
  for (size_t r = 0; r < 2 * runs; ++r) {
    const size_t run = r % runs, side = r < runs ? 0 : surfels;
    size[r] = runSize(surfels, run);
    deviation[r] = runDeviation(sideRadiance.subspan(side + run * kSurfelRun, size[r]));
  }
  deviation = pooledDeviations(deviation, runs);
  // The defensive mixture: half the rays spread evenly, half by deviation. A run's few
  // one-ray estimates can miss a bright spot its sides do see; the even half bounds any
  // side's variance at twice what the uniform plan gives it.
  double weighted = 0.0;
  for (size_t r = 0; r < 2 * runs; ++r) weighted += size[r] * deviation[r];
  const double mean = weighted / (2.0 * static_cast<double>(surfels));
  for (double& d : deviation) d = (1.0 - kEvenShare) * d + kEvenShare * mean;
  const int rays = std::max(meanRays, 1);
  const double budget = 2.0 * static_cast<double>(surfels) * rays;
  plan.perRun = neymanCounts(deviation, size, budget, 1, kMaxRaysPerMean * rays);
  return plan;
}

}  // namespace lvox
