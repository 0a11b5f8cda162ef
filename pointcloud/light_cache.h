#pragma once
// Direct-light cache (phase 1, Gibson 2011 4.1): every surfel and every lvoxel cell stores
// the light it receives straight from the light sources, computed by the caller's closures
// (the renderer's shadow-ray code), in parallel; then the cluster aggregates are rebuilt.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>
#include <type_traits>
#include <vector>

#include "pointcloud/anderson_mixing.h"
#include "pointcloud/gather.h"
#include "pointcloud/gather_operator.h"
#include "pointcloud/pointcloud_settings.h"
#include "pointcloud/surfel_rays.h"
#include "src/core/collective.h"
#include "src/core/progress.h"

namespace lvox {

struct SurfelLightQuery {
  uint32_t index;  // in the cloud's (octree) order
  Vec3 position;
  Vec3 normal;  // the side being lit: the surfel's normal or its negation
  RGB albedo;
};

// One occupied cell of the lvoxels' light (lvoxels of overlapping media share it).
struct LvoxelLightQuery {
  uint32_t slot;
  Vec3 centre;
};

// surfelRadiance(const SurfelLightQuery&) -> RGB: outgoing radiance [W/(m^2 sr)] of the
//   side `normal` points to, e.g. albedo/pi * sum of unoccluded light * cos (+ emission).
//   Called once per side (surfaces are two-sided).
// lvoxelInScatter(const LvoxelLightQuery&) -> RGB: in-scattered radiance from the lights
//   at the cell centre, integral of phase * L_direct over the sphere [W/(m^2 sr)] (for a
//   point light: phase * I * Tr / d^2), WITHOUT the sigma_s factor: the light's first
//   coefficient. Or lvoxelInScatter(const LvoxelLightQuery&, RGB* out), which writes all
//   of the light's coefficients (LvoxelLight::coefficients(); spherical_harmonics.h) of the
//   incident direct light.
// Over several ranks (`team`, every rank holding the same cloud), each computes the
// surfels of its blocks (block b of kDirectBlock surfels on rank b % size) and the sums
// over the ranks give every rank every surfel's light, exactly as one process computes it.
inline constexpr size_t kDirectBlock = 256;
template <class SurfelFn, class LvoxelFn>
void cacheDirectLight(PointCloud& cloud, const SurfelFn& surfelRadiance,
                      const LvoxelFn& lvoxelInScatter, Collective& team = singleProcess()) {
  CloudSurfels& s = cloud.mutableSurfels();
  const size_t blocks = (s.size() + kDirectBlock - 1) / kDirectBlock;
  const auto ranks = static_cast<size_t>(team.size());
  Progress::global().addWork(blocks);
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    Progress::global().advance(1);
    const bool mine = b % ranks == static_cast<size_t>(team.rank());
    for (size_t i = b * kDirectBlock; i < std::min(s.size(), (b + 1) * kDirectBlock); ++i) {
      if (!mine) {
        s.radianceFront[i] = s.radianceBack[i] = RGB(0.0f);
        continue;
      }
      const auto idx = static_cast<uint32_t>(i);
      const RGB front =
          surfelRadiance(SurfelLightQuery{idx, s.position(i), s.normal(i), s.albedo[i]});
      const RGB back =
          surfelRadiance(SurfelLightQuery{idx, s.position(i), -s.normal(i), s.albedo[i]});
      s.radianceFront[i] = isFinite(front) ? front : RGB(0.0f);
      s.radianceBack[i] = isFinite(back) ? back : RGB(0.0f);
    }
  });
  team.sum(floatsOf(s.radianceFront));
  team.sum(floatsOf(s.radianceBack));
  LvoxelLight& light = cloud.mutableLvoxels().light;
  tbb::parallel_for(size_t(0), light.occupiedCount(), [&](size_t i) {
    const auto slot = static_cast<uint32_t>(i);
    RGB* out = light.directInScatter(slot);
    if constexpr (std::is_invocable_v<const LvoxelFn&, const LvoxelLightQuery&, RGB*>) {
      lvoxelInScatter(LvoxelLightQuery{slot, light.centre(slot)}, out);
    } else {
      out[0] = lvoxelInScatter(LvoxelLightQuery{slot, light.centre(slot)});
      std::fill(out + 1, out + light.coefficients(), RGB(0.0f));
    }
    for (int k = 0; k < light.coefficients(); ++k)
      if (!isFinite(out[k])) out[k] = RGB(0.0f);
  });
  cloud.updateAggregates();
}

// Stores per-lvoxel gathered in-scatter as its cell's multiple scattering: the mean over
// the lvoxels of the cell (one per medium overlapping there). `gathered` holds `count`
// coefficients per lvoxel (the first `count` of the cell's); `update(value, next, k)`
// writes coefficient k.
template <class Update>
void storeMultiScatter(LvoxelSet& l, const RGB* gathered, int count, Update&& update) {
  const auto stride = static_cast<size_t>(count);
  std::vector<RGB> sum(l.light.occupiedCount() * stride, RGB(0.0f));
  std::vector<int> lvoxels(l.light.occupiedCount(), 0);
  for (size_t i = 0; i < l.size(); ++i) {
    for (size_t k = 0; k < stride; ++k) sum[l.slot[i] * stride + k] += gathered[i * stride + k];
    ++lvoxels[l.slot[i]];
  }
  for (size_t s = 0; s < lvoxels.size(); ++s) {
    if (lvoxels[s] == 0) continue;
    RGB* cell = l.light.multiScatter(static_cast<uint32_t>(s));
    for (size_t k = 0; k < stride; ++k)
      update(cell[k], sum[s * stride + k] / static_cast<float>(lvoxels[s]), k);
  }
}

// Multiple scattering between lvoxels: `bounces` Jacobi passes, each gathering the
// in-scattered radiance at every lvoxel centre from the cloud as it stands (surfels'
// cached radiance plus the lvoxels' current sources) into its cell's multiScatter. One
// pass adds the light scattered once more by the medium and the light from lit surfels.
// The gathers trace their rays anew each pass (cacheInterreflection keeps them) and store
// the isotropic in-scatter only (the first coefficient).
template <class Phase>
void cacheMultipleScattering(PointCloud& cloud, const Phase& phase, const GatherOptions& options,
                             int bounces, uint64_t seed) {
  LvoxelSet& l = cloud.mutableLvoxels();
  std::vector<RGB> next(l.size());
  for (int b = 0; b < bounces; ++b) {
    tbb::parallel_for(size_t(0), l.size(), [&](size_t i) {
      Rng rng(seed, (static_cast<uint64_t>(b) << 40) ^ i);
      TraversalScratch scratch;
      // Isotropic cache: the viewer direction is irrelevant for isotropic phases and is
      // fixed to +z otherwise (the cache stores no directional dependence).
      const RGB in =
          gatherInScatter(cloud, l.position[i], Vec3(0, 0, 1), phase, options, rng, scratch);
      next[i] = isFinite(in) ? in : RGB(0.0f);
    });
    storeMultiScatter(l, next.data(), 1, [](RGB& value, const RGB& v, size_t) { value = v; });
    cloud.updateAggregates();
  }
}

// How many interreflection passes run. Once only the slowest mode of the bounce series is
// left, each pass changes the cloud by about `ratio` times what the one before did, and the
// passes not run would add about change * ratio / (1 - ratio): the light still missing.
// Thick, bright media converge slowly (ratio about 0.9 in a closed room of albedo-0.95
// smoke), thin ones fast (0.66 in the atrium), so a fixed count either stops short or runs
// passes that change nothing (docs/pcb.md, "How many passes").
struct InterreflectionPasses {
  int max = 0;
  // Stop after the pass whose estimated rest is below this share of the cloud's light
  // (the sum of its radiance over surfel sides and lvoxels); 0: always `max` passes.
  double tolerance = 0.0;
  // The last pass adds that estimated rest, each value moving by its change / (1 - ratio).
  bool geometricTail = false;
  // With a tolerance: Anderson mixing of the cloud's state over this many past passes
  // (AndersonMixing) after kPlainPasses plain ones; 0: plain passes only. The passes then
  // stop once the last one's change, as the rest it leaves (below), is under the tolerance;
  // no tail is added.
  int andersonDepth = 0;
  static constexpr int kPlainPasses = 3;
  // Mixing chosen by the passes themselves (kAutoBounceMixing): they run plain, and after
  // kAutoDecisionPass of them, if the plain stop rule's own prediction (plainPassesLeft)
  // leaves kAutoMixingPasses or more to run, they go on mixed at depth kAutoDepth. A mix
  // sweeps the state twice, about a third of a pass, and where few passes are left it
  // saves none: mixed from the start the lamp hall took 9 -> 10 passes, the gallery
  // 13 -> 11, Sponza 16 -> 14, the closed room 43 -> 17 and the open town 25 -> 11
  // (docs/results.md, stop 56). After 6 passes the prediction is 1.4-6.6 passes on the
  // first four, 12.9 and 15.0 on the last two: the ratio is still rising then, so it falls
  // short of the passes the plain rule runs (37 and 19 more there), never above them.
  bool autoMixing = false;
  static constexpr int kAutoDecisionPass = 6;
  static constexpr double kAutoMixingPasses = 10.0;
  static constexpr int kAutoDepth = 3;
  // Under mixing, the rest a pass leaves is taken as its change times r / (1 - r), r the
  // larger of the plain passes' ratio and this floor: their early ratios fall short of the
  // series' (0.59 after the 3 plain passes in the closed room, 0.90 at 40), and mixed
  // passes show no ratio to measure. Where the series' ratio is above the floor (a closed
  // room whiter than 0.95) the rest is underestimated by up to (1 - 0.95) / (1 - ratio).
  static constexpr double kMixedRatioFloor = 0.95;

  InterreflectionPasses(int passes) : max(passes) {}  // NOLINT(google-explicit-constructor)
  // `anderson`: a depth, 0, or kAutoBounceMixing (pointcloud_settings.h).
  InterreflectionPasses(int passes, double restTolerance, bool tail, int anderson = 0)
      : max(passes),
        tolerance(restTolerance),
        geometricTail(tail),
        andersonDepth(anderson == kAutoBounceMixing ? kAutoDepth : anderson),
        autoMixing(anderson == kAutoBounceMixing) {}
  // Mixing from the start (after kPlainPasses plain passes), whatever the passes show.
  bool mixes() const { return andersonDepth > 0 && tolerance > 0.0 && !autoMixing; }
  // Mixing left to the passes (autoMixing), which need a tolerance to stop by.
  bool mayMix() const { return autoMixing && tolerance > 0.0; }
};

// The ratio of the bounce series from the changes of the passes so far (absolute sums, in
// order): the larger of the last two ratios, since they rise towards the slowest mode's as
// the faster modes die out. 0 while fewer than three passes give no two ratios, or when
// the series does not shrink.
inline double bounceRatio(const std::vector<double>& changes) {
  const size_t k = changes.size();
  if (k < 3 || changes[k - 2] <= 0.0 || changes[k - 3] <= 0.0) return 0.0;
  const double ratio = std::max(changes[k - 1] / changes[k - 2], changes[k - 2] / changes[k - 3]);
  return std::isfinite(ratio) && ratio < 1.0 ? ratio : 0.0;
}

// How many more plain passes the stop rule (cacheInterreflection) would run, from the
// passes' absolute changes so far, the cloud's light `total` after the last and the
// tolerance: at the series' ratio r (bounceRatio) the last change c shrinks to c r^n after
// n passes, and the rule stops once c r^n r^2 / (1 - r), the rest the next pass would
// leave, is below the tolerance times the light then, about total + c r / (1 - r) (a
// pass's change adds to the light while the series rises). 0 where the ratio is not known
// yet or the rule would stop now.
inline double plainPassesLeft(const std::vector<double>& changes, double total, double tolerance) {
  const double r = bounceRatio(changes);
  const double c = changes.empty() ? 0.0 : changes.back();
  if (r <= 0.0 || c <= 0.0) return 0.0;
  const double light = total + c * r / (1.0 - r);
  const double shrink = tolerance * light * (1.0 - r) / (c * r * r);
  return shrink < 1.0 ? std::log(shrink) / std::log(r) : 0.0;
}

struct InterreflectionStats {
  size_t gatherRays = 0;  // traced once
  size_t entries = 0;     // weights kept (GatherOperator)
  size_t operatorBytes = 0;
  // sum |L_last - L_previous| / sum |L_last| over surfels' radiance and lvoxels' in-scatter:
  // what the last pass still changed, i.e. roughly the share of light still missing.
  double lastPassChange = 0.0;
  std::vector<double> passChanges;  // the same for every pass, in order
  int passes = 0;                   // run
  int mixedPasses = 0;              // of those, the ones whose result Anderson mixing moved
  // Under auto mixing: the plain passes the stop rule predicted were left at the decision
  // pass (plainPassesLeft); 0 where the passes did not get that far.
  double predictedPasses = 0.0;
  double ratio = 0.0;               // of the series, where the passes estimated it
  double tail = 0.0;             // the share of the light the last pass added as the geometric rest
  double traceSeconds = 0.0;     // tracing the gather rays into the operator (split)
  double exchangeSeconds = 0.0;  // over ranks: summing the passes' radiance (waits included)
};

// The passes' state as one vector: the surfels' radiance (fronts, backs), then the first
// `count` multiple-scattering coefficients of every occupied lvoxel cell.
inline size_t interreflectionStateSize(const PointCloud& cloud, size_t count) {
  return 3 * (2 * cloud.surfels().size() + cloud.lvoxels().light.occupiedCount() * count);
}
inline void packInterreflectionState(PointCloud& cloud, size_t count, std::vector<float>& out) {
  const CloudSurfels& s = cloud.surfels();
  const LvoxelLight& light = cloud.lvoxels().light;
  const size_t n = s.size();
  out.resize(interreflectionStateSize(cloud, count));
  float* o = out.data();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const auto& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      std::copy_n(&s.radianceFront[i].x, 3, o + 3 * i);
      std::copy_n(&s.radianceBack[i].x, 3, o + 3 * (n + i));
    }
  });
  float* cells = o + 6 * n;
  tbb::parallel_for(
      tbb::blocked_range<uint32_t>(0, static_cast<uint32_t>(light.occupiedCount()), 1024),
      [&](const auto& r) {
        for (uint32_t c = r.begin(); c < r.end(); ++c)
          std::copy_n(&light.multiScatter(c)->x, 3 * count, cells + 3 * count * c);
      });
}
// The inverse, with the radiance and the cells' mean in-scatter clamped at zero (a mixed
// state can undershoot; the higher coefficients are signed).
inline void unpackInterreflectionState(PointCloud& cloud, size_t count,
                                       const std::vector<float>& in) {
  CloudSurfels& s = cloud.mutableSurfels();
  LvoxelLight& light = cloud.mutableLvoxels().light;
  const size_t n = s.size();
  const float* i0 = in.data();
  auto at = [](const float* p) { return nonNegative(RGB(p[0], p[1], p[2])); };
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const auto& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      s.radianceFront[i] = at(i0 + 3 * i);
      s.radianceBack[i] = at(i0 + 3 * (n + i));
    }
  });
  const float* cells = i0 + 6 * n;
  tbb::parallel_for(
      tbb::blocked_range<uint32_t>(0, static_cast<uint32_t>(light.occupiedCount()), 1024),
      [&](const auto& r) {
        for (uint32_t c = r.begin(); c < r.end(); ++c) {
          RGB* cell = light.multiScatter(c);
          const float* v = cells + 3 * count * c;
          cell[0] = at(v);
          for (size_t k = 1; k < count; ++k) cell[k] = RGB(v[3 * k], v[3 * k + 1], v[3 * k + 2]);
        }
      });
}

// Interreflection: Jacobi passes over the whole cloud (InterreflectionPasses: how many). Each pass
// gathers, from the cloud as it stands, the irradiance at both sides of every surfel (its radiance
// becomes direct + albedo E / pi) and the in-scattered radiance at every lvoxel (its
// multiScatter), then refreshes the aggregates: pass n adds the light that bounced n
// more times, between surfaces and media alike. The direct radiance is the surfels'
// radiance on entry (call cacheDirectLight first).
//
// The gather rays are traced once, into a GatherOperator, and every pass applies it: the
// same rays serve every bounce. Few rays per surfel suffice when the camera's final
// gather averages over many surfels; the noise of each is then averaged out.
//
// `sideRays`: how many rays each surfel side traces and where they point (surfel_rays.h);
// null: surfelOptions.samples each, jittered independently.
//
// `reserve(bytes)` holds the operator's memory block by block; `reserveMixing(bytes)` the
// mixer's state (2 m + 4 copies of the cloud's), false if it does not fit: auto mixing
// then stays plain (the caller throws instead under an explicit depth). Either may be empty.
//
// Over several ranks (`team`, every rank holding the same cloud) each traces and applies
// its share of the operator's rows, and every pass sums the gathered radiance over the
// ranks before updating the cloud: every rank ends with the cloud one process computes.
// The stats' rays are all ranks'; its entries and bytes this rank's share.
template <class Phase>
InterreflectionStats cacheInterreflection(
    PointCloud& cloud, const Phase& phase, const GatherOptions& surfelOptions,
    const GatherOptions& lvoxelOptions, const InterreflectionPasses& passes, uint64_t seed,
    Collective& team = singleProcess(), const std::function<void(uint64_t)>& reserve = {},
    const SurfelRays* sideRays = nullptr, const std::function<bool(uint64_t)>& reserveMixing = {}) {
  InterreflectionStats stats;
  if (passes.max <= 0) return stats;
  CloudSurfels& s = cloud.mutableSurfels();
  LvoxelSet& l = cloud.mutableLvoxels();
  const size_t n = s.size(), m = l.size();
  // Rows: surfel fronts [0, n), backs [n, 2n), lvoxels [2n, 2n + m).
  // What the rows' hits reflect from the delta lights (GatherOptions::hitLight) and what
  // their escaping rays see (GatherOptions::background, each kind of row its own) are the
  // same every pass: each surfel side's share joins its direct radiance (light that
  // bounced once off the hit, or the sky's), each lvoxel's is added to its gathered light.
  const bool constants = surfelOptions.hitLight || lvoxelOptions.hitLight ||
                         !isBlack(surfelOptions.background) || !isBlack(lvoxelOptions.background);
  const auto count = static_cast<size_t>(GatherColumns(cloud).coefficients);
  std::vector<RGB> directFront(n, RGB(0.0f)), directBack(n, RGB(0.0f));
  std::vector<RGB> lvoxelConstant(constants ? m * count : 0, RGB(0.0f));
  // Lvoxels alone in their cell take their own cube's weights from own_cube.h: where media
  // overlap, the cell's cubes shade each other in the rays' order, which it leaves out.
  std::vector<uint8_t> sharesCell;
  if (lvoxelOptions.ownCubeQuadrature) {
    std::vector<uint8_t> perSlot(l.light.occupiedCount(), 0);
    for (size_t i = 0; i < m; ++i) perSlot[l.slot[i]] = perSlot[l.slot[i]] ? 2 : 1;
    sharesCell.resize(m);
    for (size_t i = 0; i < m; ++i) sharesCell[i] = perSlot[l.slot[i]] > 1;
  }
  const auto traceStart = std::chrono::steady_clock::now();
  const GatherOperator gathers(
      cloud, 2 * n + m,
      [&](size_t row, GatherRecorder& recorder, TraversalScratch& scratch) {
        RGB constant[kShCoefficients];
        std::fill(constant, constant + kShCoefficients, RGB(0.0f));
        if (constants) {
          recorder.constant = constant;
          recorder.background = row < 2 * n ? &surfelOptions.background : &lvoxelOptions.background;
        }
        if (row < 2 * n) {
          const size_t i = row % n;
          const bool front = row < n;
          Rng rng(seed ^ 0x5f1ce5u, (static_cast<uint64_t>(front ? 0 : 1) << 40) ^ i);
          GatherOptions options = surfelOptions;
          if (sideRays) {
            options.samples = sideRays->raysOf(i, front);
            options.strata = sideRays->strataOf(i, front);
          }
          gatherIrradianceInto(cloud, s.position(i), front ? s.normal(i) : -s.normal(i), options,
                               rng, scratch, recorder);
          (front ? directFront : directBack)[i] = s.albedo[i] * nonNegative(constant[0]) * kInvPi;
        } else {
          const size_t i = row - 2 * n;
          Rng rng(seed, i);
          // The incident light, uniformly over the sphere: each lvoxel applies its own
          // phase when it sends its light on (LvoxelSet::sourceCoefficients), so the row
          // keeps the light's mean, or its spherical harmonics in anisotropic media.
          GatherOptions options = lvoxelOptions;
          if (options.ownCubeQuadrature && !sharesCell[i]) options.ownLvoxel = static_cast<long>(i);
          gatherInScatterInto(cloud, l.position[i], Vec3(0, 0, 1), phase, options, rng, scratch,
                              recorder);
          if (constants) std::copy(constant, constant + count, &lvoxelConstant[i * count]);
        }
      },
      team.rank(), team.size(), reserve);
  if (constants && team.size() > 1) {  // each rank traced its own rows' share
    team.sum(floatsOf(directFront));
    team.sum(floatsOf(directBack));
    team.sum(floatsOf(lvoxelConstant));
  }
  for (size_t i = 0; i < n; ++i) {
    directFront[i] += s.radianceFront[i];
    directBack[i] += s.radianceBack[i];
  }
  stats.traceSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - traceStart).count();
  stats.gatherRays = (sideRays ? sideRays->totalRays()
                               : 2 * n * static_cast<size_t>(std::max(surfelOptions.samples, 1))) +
                     m * static_cast<size_t>(std::max(lvoxelOptions.samples, 1)) *
                         static_cast<size_t>(1 + nearFieldRaysPerRay(lvoxelOptions));
  stats.entries = gathers.entries();
  stats.operatorBytes = gathers.memoryBytes();

  // Lvoxel rows gather coefficients() values each: the spherical-harmonic coefficients of
  // their incident light where lvoxels scatter anisotropically, else its mean.
  LVOX_CHECK(count == static_cast<size_t>(gathers.coefficients()),
             "the operator's coefficients differ from its columns'");
  GatherValues values;
  std::vector<RGB> gathered, lvoxelGathered(m * count);
  // What each pass changed, summed per block of rows, then in block order: deterministic.
  const size_t blocks = gathers.blockCount();
  std::vector<double> blockChange(blocks), blockTotal(blocks);
  // A value moves to `next`, or by `step` times that change on a pass that adds the
  // geometric rest; what the pass itself changed is summed.
  double step = 1.0;
  auto updateInto = [&step](double& changeSum, double& totalSum, RGB& value, const RGB& next,
                            bool nonNegativeValue) {
    const RGB finite = isFinite(next) ? next : RGB(0.0f);
    const RGB d = finite - value;
    changeSum += std::abs(d.x) + std::abs(d.y) + std::abs(d.z);
    totalSum += std::abs(finite.x) + std::abs(finite.y) + std::abs(finite.z);
    value = step == 1.0 ? finite : value + d * static_cast<float>(step);
    if (nonNegativeValue) value = nonNegative(value);
  };
  // One row's gathered radiance into the cloud (surfel radiance in place: the gathers read
  // the snapshot `values` only); a surfel's irradiance is the first coefficient. A row is
  // a sum of weights times values, and surfel clusters' weights can be negative (their
  // higher harmonics), so its mean is clamped at zero as every per-ray radiance is.
  auto updateRow = [&](size_t row, const RGB* g) {
    const size_t b = row / GatherOperator::kRowsPerBlock;
    const RGB* c = row >= 2 * n && constants ? &lvoxelConstant[(row - 2 * n) * count] : nullptr;
    const RGB mean = nonNegative(c ? g[0] + c[0] : g[0]);
    if (row < n)
      updateInto(blockChange[b], blockTotal[b], s.radianceFront[row],
                 directFront[row] + s.albedo[row] * mean * kInvPi, true);
    else if (row < 2 * n)
      updateInto(blockChange[b], blockTotal[b], s.radianceBack[row - n],
                 directBack[row - n] + s.albedo[row - n] * mean * kInvPi, true);
    else {
      RGB* out = &lvoxelGathered[(row - 2 * n) * count];
      for (size_t k = 0; k < count; ++k) out[k] = c ? g[k] + c[k] : g[k];
      out[0] = mean;
    }
  };
  std::vector<double> changes;  // absolute, per pass
  double lastTotal = 0.0;
  // Mixing: the state before the pass (x), after it (g), and the mixer's history.
  // Under auto mixing (passes.mayMix) the passes are plain until the decision pass, whose
  // state before is kept in case they go on mixed; the mixer's first pass is then the next.
  bool mixes = false;
  int plainPasses = InterreflectionPasses::kPlainPasses;
  std::vector<float> stateBefore, stateAfter;
  std::optional<AndersonMixing> mixing;
  double plainRatio = 0.0;
  auto startMixing = [&] {
    const size_t size = interreflectionStateSize(cloud, count);
    const uint64_t bytes =
        2 * size * sizeof(float) + AndersonMixing::bytesFor(size, passes.andersonDepth);
    // Every rank mixes or none: their budgets differ by their shares of the operator.
    uint64_t fits[1] = {!reserveMixing || reserveMixing(bytes) ? 1u : 0u};
    if (team.size() > 1) team.sum(std::span<uint64_t>(fits));
    if (fits[0] != static_cast<uint64_t>(team.size())) return false;
    mixing.emplace(size, passes.andersonDepth);
    return mixes = true;
  };
  if (passes.mixes()) startMixing();
  const auto decides = [&](int pass) {
    return passes.mayMix() && pass + 1 == InterreflectionPasses::kAutoDecisionPass;
  };
  for (int pass = 0; pass < passes.max; ++pass) {
    // Is this the last pass? Its change is predicted as the last one's times the ratio.
    // Under mixing that is decided after the pass, from its own change.
    const double ratio = bounceRatio(changes);
    const bool converged =
        !mixes && passes.tolerance > 0.0 && ratio > 0.0 &&
        changes.back() * ratio * ratio / (1.0 - ratio) < passes.tolerance * lastTotal;
    const bool last = pass + 1 == passes.max || converged;
    step = !mixes && last && passes.geometricTail && ratio > 0.0 ? 1.0 / (1.0 - ratio) : 1.0;
    if (mixes || decides(pass)) packInterreflectionState(cloud, count, stateBefore);
    // The snapshot; the backgrounds, if any, are in the rows' constants.
    gathers.valuesInto(cloud, RGB(0.0f), values);
    std::fill(blockChange.begin(), blockChange.end(), 0.0);
    std::fill(blockTotal.begin(), blockTotal.end(), 0.0);
    if (team.size() == 1) {
      gathers.forEachRow(values, updateRow);  // no vector of all rows
    } else {
      // Every rank's share summed: the whole gathered vector is exchanged.
      gathers.apply(values, gathered);
      const auto exchangeStart = std::chrono::steady_clock::now();
      team.sum(floatsOf(gathered));
      stats.exchangeSeconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - exchangeStart).count();
      tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
        const size_t end = std::min(gathers.rows(), (b + 1) * GatherOperator::kRowsPerBlock);
        for (size_t r = b * GatherOperator::kRowsPerBlock; r < end; ++r)
          updateRow(r, &gathered[r * count]);
      });
    }
    double change = 0.0, total = 0.0;
    for (size_t b = 0; b < blocks; ++b) {
      change += blockChange[b];
      total += blockTotal[b];
    }
    // What the pass changed is measured on the first coefficient (the mean) only; the
    // higher coefficients of anisotropic lvoxels are signed.
    double ignored = 0.0;
    storeMultiScatter(l, lvoxelGathered.data(), static_cast<int>(count),
                      [&](RGB& value, const RGB& next, size_t k) {
                        updateInto(k == 0 ? change : ignored, k == 0 ? total : ignored, value, next,
                                   k == 0);
                      });
    stats.lastPassChange = total > 0.0 ? change / total : 0.0;
    stats.passChanges.push_back(stats.lastPassChange);
    changes.push_back(change);
    lastTotal = total;
    stats.passes = pass + 1;
    if (step != 1.0) stats.tail = stats.lastPassChange * ratio / (1.0 - ratio);
    bool done = last || (passes.tolerance > 0.0 && change == 0.0);
    if (!done && decides(pass)) {
      stats.predictedPasses = plainPassesLeft(changes, total, passes.tolerance);
      // This pass gives the mixer its history: the next one's result is mixed.
      if (stats.predictedPasses >= InterreflectionPasses::kAutoMixingPasses && startMixing())
        plainPasses = pass + 2;
    }
    if (mixes && !done) {
      if (pass + 1 <= plainPasses) plainRatio = bounceRatio(changes);
      const double r = std::max(plainRatio, InterreflectionPasses::kMixedRatioFloor);
      done = pass + 1 >= plainPasses && change * r / (1.0 - r) < passes.tolerance * total;
      if (!done && pass + 1 >= plainPasses - 1) {
        // From the pass before the last plain one on the mixer keeps the history (its first
        // mix is plain), so the first plainPasses passes are plain and the next one mixes.
        packInterreflectionState(cloud, count, stateAfter);
        mixing->mix(stateBefore, stateAfter);
        if (mixing->used() > 0) {
          unpackInterreflectionState(cloud, count, stateBefore);
          ++stats.mixedPasses;
        }
      }
    }
    cloud.updateAggregates();
    // A pass that changed nothing leaves nothing for the next ones (no bounce returns
    // light: black surfaces, no scattering media).
    if (done) break;
  }
  stats.ratio = mixes ? plainRatio : bounceRatio(changes);
  return stats;
}

// The plan of the surfel sides' rays (surfel_rays.h) from a preview of the interreflection:
// one ray per side and per lvoxel (no near field, no own-cube quadrature), through
// kPreviewPasses passes (fewer where `passes` has fewer), on a stream of its own. Each side's
// one-ray estimate of the light it reflects after the bounces (its converged radiance less its
// direct one) gives its run's deviation. The cloud is put back as it came (its surfels' radiance,
// its lvoxels' multiple scattering) and `previewRays` counts the preview's rays.
inline constexpr int kPreviewPasses = 4;
template <class Phase>
SurfelRays previewSurfelRays(PointCloud& cloud, const Phase& phase,
                             const GatherOptions& surfelOptions, const GatherOptions& lvoxelOptions,
                             const InterreflectionPasses& passes, int meanRays, uint64_t seed,
                             Collective& team, uint64_t& previewRays) {
  CloudSurfels& s = cloud.mutableSurfels();
  LvoxelLight& light = cloud.mutableLvoxels().light;
  const size_t n = s.size(), cells = light.occupiedCount();
  const auto coefficients = static_cast<size_t>(light.coefficients());
  const std::vector<RGB> front = s.radianceFront, back = s.radianceBack;
  std::vector<RGB> multi(cells * coefficients);
  for (size_t c = 0; c < cells; ++c)
    std::copy_n(light.multiScatter(static_cast<uint32_t>(c)), coefficients,
                &multi[c * coefficients]);

  const uint64_t previewSeed = splitMix64(seed ^ 0x9e71e3u);
  const SurfelRays oneRay = uniformSurfelRays(n, 1, previewSeed);
  GatherOptions lvoxelPreview = lvoxelOptions;
  lvoxelPreview.samples = 1;
  lvoxelPreview.nearSamples = 0;
  lvoxelPreview.ownCubeQuadrature = false;
  // The first bounces set where the light varies; a one-ray operator's series does not
  // shrink steadily enough for the pass plan, which ran all 64 passes (2 s in the closed
  // room) and gave the same plans as 4 (docs/results.md, stop 53).
  const InterreflectionPasses previewPasses(std::min(passes.max, kPreviewPasses));
  const InterreflectionStats stats = cacheInterreflection(
      cloud, phase, surfelOptions, lvoxelPreview, previewPasses, previewSeed, team, {}, &oneRay);
  previewRays = stats.gatherRays;

  std::vector<float> reflected(2 * n);
  auto mean = [](const RGB& c) { return (c.x + c.y + c.z) / 3.0f; };
  for (size_t i = 0; i < n; ++i) {
    reflected[i] = mean(s.radianceFront[i] - front[i]);
    reflected[n + i] = mean(s.radianceBack[i] - back[i]);
  }
  s.radianceFront = front;
  s.radianceBack = back;
  for (size_t c = 0; c < cells; ++c)
    std::copy_n(&multi[c * coefficients], coefficients,
                light.multiScatter(static_cast<uint32_t>(c)));
  cloud.updateAggregates();
  return plannedSurfelRays(reflected, meanRays, seed);
}

}  // namespace lvox
