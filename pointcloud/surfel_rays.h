#pragma once
// How many rays each surfel side's interreflection gather traces, and where they point
// (docs/pcb.md, "Rays where the cloud is noisy").
//
// The cloud's noise is the noise of its surfels' few gather rays, and it is uneven: a side
// that sees a sunlit patch beside shade, or a lamp's bright wall, is far noisier than one
// that sees an evenly lit room. For one total of rays, the sum of the sides' variances (of
// the radiance they reflect: what their error adds to what sees them) is least when each
// side traces rays in proportion to its standard deviation (Neyman allocation). Half the
// rays are still spread evenly (a defensive mixture): measured on lamp-lit rooms, where a
// run's one-ray estimates often miss the bright spots near the lamps, Neyman alone left
// the image noisier than even rays; the mixture is as good as them there and keeps most
// of Neyman's gain in sunlit scenes (docs/results.md, stop 53).
//
// The deviations come from a preview of the interreflection (previewSurfelRays,
// light_cache.h): one ray per side, run through the bounces, so that a side lit only by
// light that bounced twice has its noise measured too; a pilot on the direct light alone
// missed that and gained a third as much. Sides are planned by run: kSurfelRun consecutive
// surfels in the cloud's Morton order, which lie close together and mostly on one plane.
// A run's one-ray sides pool into one deviation, itself pooled with its neighbouring runs'
// (kPoolRuns), so the plan hardly depends on any one side's ray, and no preview ray is
// reused: the operator's rays are drawn independently of the plan, and each side's gather
// is as unbiased as the uniform plan's whatever count it gets.
//
// A run also shares its directions: surfel k of a run of n rays per side takes points
// [k P, k P + n) of one Owen-scrambled (0,2)-sequence (P the power of two at or above n),
// so each side alone is stratified and the run's sides together cover the hemisphere as
// evenly as one gather with all their rays (GatherOptions::strata; interleaved sampling).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "pointcloud/gather.h"

namespace lvox {

inline constexpr size_t kSurfelRun = 16;
// A side traces at least one ray and at most this many times the mean.
inline constexpr int kMaxRaysPerMean = 16;
// The share of the rays spread evenly over the sides; the rest go by deviation.
inline constexpr double kEvenShare = 0.5;
// A run's deviation is pooled with this many runs on either side of it (surfel_rays.cpp).
inline constexpr size_t kPoolRuns = 8;

struct SurfelRays {
  size_t surfels = 0;
  std::vector<uint32_t> perRun;  // rays per side of each run: the fronts' runs, then the backs'
  uint64_t seed = 0;             // the directions' scrambles

  size_t runs() const { return (surfels + kSurfelRun - 1) / kSurfelRun; }
  int raysOf(size_t surfel, bool front) const {
    return static_cast<int>(perRun[(front ? 0 : runs()) + surfel / kSurfelRun]);
  }
  SharedStrata strataOf(size_t surfel, bool front) const;
  uint64_t totalRays() const;  // over every side
};

// Every side `rays` rays, the runs' directions shared.
SurfelRays uniformSurfelRays(size_t surfels, int rays, uint64_t seed);

// The plan for a mean of `meanRays` rays per side, from one ray's estimate of each side's
// reflected radiance (`sideRadiance`: the fronts, then the backs; the channels' mean):
// kEvenShare of the rays evenly, the rest by the deviation of each run's estimates, within
// [1, kMaxRaysPerMean * meanRays], adding up to meanRays per side over the cloud (up to
// rounding).
SurfelRays plannedSurfelRays(std::span<const float> sideRadiance, int meanRays, uint64_t seed);

// Neyman allocation of `budget` rays over groups of `size[g]` members each of deviation
// `deviation[g]`: a count per member in [lo, hi], proportional to the deviation where the
// bounds allow, rounded in order so that the running sum stays within half a group's
// members of its target. Groups of zero deviation get lo; where every deviation is zero,
// every group gets the budget's mean.
std::vector<uint32_t> neymanCounts(std::span<const double> deviation,
                                   std::span<const uint32_t> size, double budget, int lo, int hi);

}  // namespace lvox
