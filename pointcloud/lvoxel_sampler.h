#pragma once
// Lvoxels from a medium (Gibson 2011, 4.1): march over the medium's active region on a
// grid of the given spacing and average jittered samples of the coefficients over each
// cell; by default scale them to keep the medium's mean transmittance across the cell
// (transmittanceFactor). The medium is any type with
//   Bounds3 bounds() const;                          // where sigma can be non-zero
//   const std::vector<Bounds3>& activeBoxes() const; // cells overlapping none are skipped
//   void coefficients(const Vec3& p, RGB& sigmaA, RGB& sigmaS) const;  // 0 outside
// so this library does not depend on the volume library's concrete media. A medium that
// may emit also has (EmittingMediumSampler)
//   bool emits() const;
//   RGB emissionSource(const Vec3& p) const;  // sigma_a * Le, 0 outside
// and its lvoxels carry the emission source averaged over their cube.
#include <tbb/parallel_for.h>

#include <algorithm>
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
  // Scale each cell's coefficients to keep the medium's mean transmittance across the
  // cube (detail::transmittanceFactor); false: the cell's mean coefficients.
  bool keepTransmittance = true;
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

// Each lvoxel is a homogeneous cube, and a cube of the cell's mean extinction lets less
// light through than the medium it stands for wherever the medium varies inside the cell
// (a cell its edge cuts, wisps): the mean of exp(-tau) over the lines across the cell is
// at least exp of the mean tau (Jensen). That cube also absorbs, and glows with, more
// than the medium does. With keepTransmittance the cube gets the extinction that keeps
// the mean transmittance along its sides: m x m stratified lines across the cell along
// each axis (m = samplesPerAxis), 4m jittered midpoints each, give optical depths tau_j,
// and sigma' = -ln(mean exp(-tau_j)) / side. Returned as the factor per channel from the
// cell's mean `sigmaT`, by which its sigma_a and sigma_s are scaled (its albedo kept);
// 1 where every line has the same optical depth (a homogeneous cell keeps its mean
// exactly) or the mean is 0 (docs/pcb.md, "Lvoxels that keep the cell's transmittance").
template <class Medium>
RGB transmittanceFactor(const Medium& medium, const Vec3& lo, float spacing, int m,
                        const RGB& sigmaT, Rng& rng) {
  const int steps = 4 * m;
  const float dt = spacing / static_cast<float>(steps);
  const float stratum = spacing / static_cast<float>(m);
  std::array<double, 3> sumTr{};
  std::array<float, 3> lowest{kInf, kInf, kInf}, highest{0.0f, 0.0f, 0.0f};
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int line = 0; line < m * m; ++line) {
      Vec3 p = lo;
      p[u] += (static_cast<float>(line % m) + rng.uniform()) * stratum;
      p[v] += (static_cast<float>(line / m) + rng.uniform()) * stratum;
      const float offset = rng.uniform();
      RGB tau(0.0f);
      for (int k = 0; k < steps; ++k) {
        p[axis] = lo[axis] + (static_cast<float>(k) + offset) * dt;
        RGB a(0.0f), sc(0.0f);
        medium.coefficients(p, a, sc);
        tau += (sanitized(a) + sanitized(sc)) * dt;
      }
      for (int c = 0; c < 3; ++c) {
        sumTr[c] += std::exp(-static_cast<double>(tau[c]));
        lowest[c] = std::min(lowest[c], tau[c]);
        highest[c] = std::max(highest[c], tau[c]);
      }
    }
  }
  const double lines = 3.0 * m * m;
  RGB f(1.0f);
  for (int c = 0; c < 3; ++c) {
    if (!(sigmaT[c] > 0.0f) || !(highest[c] > lowest[c] * (1.0f + 1e-5f))) continue;
    // An opaque cell (every line's exp underflowing) keeps its mean: it stops the light.
    if (!(sumTr[c] > 0.0)) continue;
    const double kept = -std::log(sumTr[c] / lines) / spacing;
    f[c] = static_cast<float>(kept / sigmaT[c]);
  }
  return f;
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
        if (settings.keepTransmittance) {
          const RGB f =
              detail::transmittanceFactor(medium, lo, settings.spacing, m, sigmaA + sigmaS, rng);
          sigmaA *= f;
          sigmaS *= f;
          if (isBlack(sigmaA + sigmaS)) continue;  // no line met the medium
        }
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
