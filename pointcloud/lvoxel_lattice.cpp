#include "pointcloud/lvoxel_lattice.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace lvox {

std::optional<LvoxelLattice> LvoxelLattice::of(const std::vector<CubeElement>& cubes) {
  if (cubes.empty() || cubes.size() > kIndexMask) return std::nullopt;
  const float h = cubes[0].halfSize;
  if (!(h > 0.0f) || !std::isfinite(h)) return std::nullopt;
  LvoxelLattice lattice;
  lattice.spacing_ = 2.0f * h;
  Vec3 lo(kInf, kInf, kInf);
  for (const CubeElement& c : cubes) {
    if (c.halfSize != h) return std::nullopt;
    lo = Vec3(std::min(lo.x, c.centre.x), std::min(lo.y, c.centre.y), std::min(lo.z, c.centre.z));
  }
  lattice.origin_ = lo - Vec3(h, h, h);
  // Each cube's cell, in double so that the check does not depend on float rounding.
  std::vector<std::pair<uint64_t, uint32_t>> byCell(cubes.size());
  std::array<int64_t, 3> top{0, 0, 0};
  std::vector<std::array<int32_t, 3>> index(cubes.size());
  for (size_t i = 0; i < cubes.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      const double f =
          (double(cubes[i].centre[a]) - double(lattice.origin_[a])) / double(lattice.spacing_) -
          0.5;
      const double k = std::round(f);
      if (!(std::abs(f - k) < 1e-3) || k > double(std::numeric_limits<int32_t>::max() / 2))
        return std::nullopt;
      index[i][a] = static_cast<int32_t>(k);
      top[a] = std::max<int64_t>(top[a], static_cast<int64_t>(k));
    }
  for (int a = 0; a < 3; ++a) {
    lattice.cells_[a] = static_cast<int32_t>(top[a] + 1);
    lattice.bricks_[a] = (lattice.cells_[a] + kBrickMask) >> kBrickShift;
  }
  const double brickCount =
      double(lattice.bricks_[0]) * double(lattice.bricks_[1]) * double(lattice.bricks_[2]);
  // The brick table covers the bounding box: a lattice much sparser than its cubes would
  // cost more than they do (the traversal then runs the heap, as for cubes off a lattice).
  if (brickCount > kMaxBricksPerCube * double(cubes.size()) + kFreeBricks) return std::nullopt;
  lattice.bounds_.lo = lattice.origin_;
  lattice.bounds_.hi = lattice.origin_ + Vec3(static_cast<float>(lattice.cells_[0]),
                                              static_cast<float>(lattice.cells_[1]),
                                              static_cast<float>(lattice.cells_[2])) *
                                             lattice.spacing_;

  // Cubes sorted by brick, then by cell in the brick, then by index.
  for (size_t i = 0; i < cubes.size(); ++i) {
    const auto& c = index[i];
    const uint64_t brick =
        lattice.brickIndex(c[0] >> kBrickShift, c[1] >> kBrickShift, c[2] >> kBrickShift);
    const uint64_t local = localIndex(c[0] & kBrickMask, c[1] & kBrickMask, c[2] & kBrickMask);
    byCell[i] = {brick << (3 * kBrickShift) | local, static_cast<uint32_t>(i)};
  }
  std::sort(byCell.begin(), byCell.end());
  lattice.brickOf_.assign(static_cast<size_t>(brickCount), 0);
  lattice.cubeList_.resize(cubes.size());
  constexpr size_t kCellsPerBrick = size_t(1) << (3 * kBrickShift);
  for (size_t n = 0; n < byCell.size(); ++n) {
    const uint64_t key = byCell[n].first;
    const size_t brick = key >> (3 * kBrickShift);
    if (lattice.brickOf_[brick] == 0) {
      lattice.cellEntries_.resize(lattice.cellEntries_.size() + kCellsPerBrick, 0);
      lattice.brickOf_[brick] = static_cast<uint32_t>(lattice.cellEntries_.size() / kCellsPerBrick);
    }
    const bool first = n == 0 || byCell[n - 1].first != key;
    const bool last = n + 1 == byCell.size() || byCell[n + 1].first != key;
    if (first)
      lattice.cellEntries_[(lattice.brickOf_[brick] - 1) * kCellsPerBrick +
                           (key & (kCellsPerBrick - 1))] = static_cast<uint32_t>(n + 1);
    lattice.cubeList_[n] = byCell[n].second | (last ? kLastInCell : 0u);
  }
  return lattice;
}

}  // namespace lvox
