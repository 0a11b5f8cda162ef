#pragma once
// Lvoxels from a medium (Gibson 2011, 4.1): march over the medium's active region on a
// grid of the given spacing and average jittered samples of the coefficients over each
// cell. The medium is any type with
//   Bounds3 bounds() const;                          // where sigma can be non-zero
//   const std::vector<Bounds3>& activeBoxes() const; // cells overlapping none are skipped
//   void coefficients(const Vec3& p, RGB& sigmaA, RGB& sigmaS) const;  // 0 outside
// so this library does not depend on the volume library's concrete media. A medium that
// may emit also has (EmittingMediumSampler)
//   bool emits() const;
//   RGB emissionSource(const Vec3& p) const;  // sigma_a * Le, 0 outside
// and its lvoxels carry the emission source averaged over their cube.
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <vector>

#include "pointcloud/lvoxel_grid.h"
#include "pointcloud/lvoxels.h"
#include "src/core/error.h"
#include "src/core/rng.h"

namespace lvox {

template <class M>
concept MediumSampler = requires(const M& m, const Vec3& p, RGB& a, RGB& s) {
  { m.bounds() } -> std::convertible_to<Bounds3>;
  { m.activeBoxes() } -> std::convertible_to<const std::vector<Bounds3>&>;
  m.coefficients(p, a, s);
};

template <class M>
concept EmittingMediumSampler = MediumSampler<M> && requires(const M& m, const Vec3& p) {
  { m.emits() } -> std::convertible_to<bool>;
  { m.emissionSource(p) } -> std::convertible_to<RGB>;
};

struct LvoxelSettings {
  float spacing = 0.0f;            // cube side, scene units, > 0
  int samplesPerAxis = 2;          // jittered samples per cell = samplesPerAxis^3 (2 -> 8)
  size_t maxLvoxels = 50'000'000;  // guards against a spacing far too small
  uint64_t seed = 1;
  // Only the slices of cells k (along z) with k % sliceCount == sliceIndex: one rank's
  // share of the sampling (docs/cluster.md). Each cell's lvoxel depends on its cell alone,
  // so the shares merged in cell order are the whole set.
  long sliceIndex = 0, sliceCount = 1;
};

namespace detail {

// One flag per cell: does the cell overlap an active box?
inline std::vector<uint8_t> activeCells(const LvoxelGrid& g, const std::vector<Bounds3>& boxes) {
  std::vector<uint8_t> active(static_cast<size_t>(g.cells[0] * g.cells[1] * g.cells[2]), 0);
  for (const Bounds3& box : boxes) {
    if (box.empty()) continue;
    std::array<long, 3> lo{}, hi{};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::clamp(static_cast<long>(std::floor((box.lo[a] - g.origin[a]) / g.spacing)), 0L,
                         g.cells[a] - 1);
      hi[a] = std::clamp(static_cast<long>(std::floor((box.hi[a] - g.origin[a]) / g.spacing)), 0L,
                         g.cells[a] - 1);
    }
    for (long k = lo[2]; k <= hi[2]; ++k)
      for (long j = lo[1]; j <= hi[1]; ++j)
        for (long i = lo[0]; i <= hi[0]; ++i) active[g.index(i, j, k)] = 1;
  }
  return active;
}

// Non-negative, finite coefficients: a broken medium must not put NaN into the cloud.
inline RGB sanitized(const RGB& c) {
  auto f = [](float v) { return std::isfinite(v) && v > 0.0f ? v : 0.0f; };
  return {f(c.x), f(c.y), f(c.z)};
}

// Mean of m^3 jittered (stratified) samples of the coefficients over the cube at `lo`, and
// of the emission source when `emission` is not null.
template <class Medium>
void averageCoefficients(const Medium& medium, const Vec3& lo, float spacing, int m, Rng& rng,
                         RGB& sigmaA, RGB& sigmaS, RGB* emission) {
  const float fm = static_cast<float>(m);
  RGB sumA(0.0f), sumS(0.0f), sumE(0.0f);
  for (int s = 0; s < m * m * m; ++s) {
    const Vec3 unit((static_cast<float>(s % m) + rng.uniform()) / fm,
                    (static_cast<float>((s / m) % m) + rng.uniform()) / fm,
                    (static_cast<float>(s / (m * m)) + rng.uniform()) / fm);
    RGB a(0.0f), sc(0.0f);
    const Vec3 p = lo + unit * spacing;
    medium.coefficients(p, a, sc);
    sumA += sanitized(a);
    sumS += sanitized(sc);
    if constexpr (EmittingMediumSampler<Medium>)
      if (emission) sumE += sanitized(medium.emissionSource(p));
  }
  const float inv = 1.0f / (fm * fm * fm);
  sigmaA = sumA * inv;
  sigmaS = sumS * inv;
  if (emission) *emission = sumE * inv;
}

template <class Medium>
bool mediumEmits(const Medium& medium) {
  if constexpr (EmittingMediumSampler<Medium>)
    return medium.emits();
  else
    return false;
}

// The lvoxels of one slice of cells (fixed k), and their cells.
struct LvoxelSlice {
  LvoxelSet lvoxels;
  std::vector<long> cells;
};

}  // namespace detail

// Lvoxels on the grid covering medium.bounds(); cells where the averaged sigma_t is zero
// in every channel are dropped. The set's light has the grid, with the lvoxels' cells
// occupied in order. The result is ordered by cell index and does not depend on the
// thread schedule.
template <MediumSampler Medium>
LvoxelSet sampleLvoxels(const Medium& medium, const LvoxelSettings& settings) {
  if (!(settings.spacing > 0.0f) || !std::isfinite(settings.spacing))
    throw InputError("pointcloud settings", "lvoxel_spacing", "must be a positive number");
  if (settings.samplesPerAxis < 1 || settings.samplesPerAxis > 8)
    throw InputError("pointcloud settings", "lvoxel_samples", "samples per axis must be 1..8");
  LvoxelSet out;
  const Bounds3 bounds = medium.bounds();
  if (bounds.empty()) return out;
  const LvoxelGrid grid = LvoxelGrid::covering(bounds, settings.spacing);
  if (grid.cellCount() > static_cast<double>(settings.maxLvoxels))
    throw InputError("pointcloud settings", "lvoxel_spacing",
                     "too small for the medium: more than maxLvoxels cells");
  const std::vector<uint8_t> active = detail::activeCells(grid, medium.activeBoxes());
  const int m = settings.samplesPerAxis;
  const float h = 0.5f * settings.spacing;
  const bool emits = detail::mediumEmits(medium);

  // One slice of cells (fixed k) per task; slices are concatenated in order.
  std::vector<detail::LvoxelSlice> slices(static_cast<size_t>(grid.cells[2]));
  tbb::parallel_for(long(0), grid.cells[2], [&](long k) {
    if (settings.sliceCount > 1 && k % settings.sliceCount != settings.sliceIndex) return;
    detail::LvoxelSlice& slice = slices[static_cast<size_t>(k)];
    for (long j = 0; j < grid.cells[1]; ++j)
      for (long i = 0; i < grid.cells[0]; ++i) {
        const size_t cell = grid.index(i, j, k);
        if (!active[cell]) continue;
        const Vec3 lo = grid.cellLow(i, j, k);
        Rng rng(settings.seed, cell);
        RGB sigmaA, sigmaS, emission;
        detail::averageCoefficients(medium, lo, settings.spacing, m, rng, sigmaA, sigmaS,
                                    emits ? &emission : nullptr);
        if (isBlack(sigmaA + sigmaS)) continue;
        if (emits) slice.lvoxels.emission.push_back(emission);
        slice.lvoxels.position.push_back(lo + Vec3(h, h, h));
        slice.lvoxels.halfSize.push_back(h);
        slice.lvoxels.sigmaA.push_back(sigmaA);
        slice.lvoxels.sigmaS.push_back(sigmaS);
        slice.cells.push_back(static_cast<long>(cell));
      }
  });
  out.light = LvoxelLight(grid);
  auto cat = [](auto& a, const auto& b) { a.insert(a.end(), b.begin(), b.end()); };
  for (const detail::LvoxelSlice& s : slices) {
    cat(out.position, s.lvoxels.position);
    cat(out.halfSize, s.lvoxels.halfSize);
    cat(out.sigmaA, s.lvoxels.sigmaA);
    cat(out.sigmaS, s.lvoxels.sigmaS);
    cat(out.emission, s.lvoxels.emission);
    for (long cell : s.cells) out.slot.push_back(out.light.occupy(cell));
  }
  return out;
}

}  // namespace lvox
