#pragma once
// The lvoxels' cubes as cells of one regular lattice, for rays that want the lvoxels only
// (ray-traced gather visibility): a 3D-DDA (Amanatides & Woo 1987) walks the cells a ray
// passes through in order, with no heap and no octree nodes (traversal.h says where the
// traversal uses it). Lvoxels of one scene share one grid (lvoxel_grid.h), so their cubes
// tile it; a cell may hold several cubes where media overlap.
//
// The cells live in bricks of 8^3: a table over the lattice's bricks says which ones hold
// cubes, and only those store their 512 cells, so a sparse cloud costs memory where it
// has lvoxels, not over its bounding box.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "pointcloud/ray_element.h"
#include "src/core/math.h"

namespace lvox {

class LvoxelLattice {
 public:
  // A cube index in the per-cell lists has this bit set when it is its cell's last.
  static constexpr uint32_t kLastInCell = 1u << 31;
  static constexpr uint32_t kIndexMask = kLastInCell - 1;

  // The lattice the cubes lie on: all of one size, their centres at the cells' centres
  // (within 1/1000 of a cell); nothing when they do not (cubes placed by hand), or when
  // their bounding box holds more than kMaxBricksPerCube bricks per cube beyond
  // kFreeBricks (its brick table would outweigh the cubes: 4 bytes per brick).
  static std::optional<LvoxelLattice> of(const std::vector<CubeElement>& cubes);
  static constexpr double kMaxBricksPerCube = 8.0;
  static constexpr double kFreeBricks = 65536.0;

  float spacing() const { return spacing_; }
  const Bounds3& bounds() const { return bounds_; }
  const std::array<int32_t, 3>& cells() const { return cells_; }
  // The cube indices of cell (i, j, k) (the last has kLastInCell set), or null when it
  // holds none.
  const uint32_t* cubesIn(int32_t i, int32_t j, int32_t k) const {
    const uint32_t brick =
        brickOf_[brickIndex(i >> kBrickShift, j >> kBrickShift, k >> kBrickShift)];
    if (brick == 0) return nullptr;
    const uint32_t entry = cellEntries_[(size_t(brick - 1) << (3 * kBrickShift)) +
                                        localIndex(i & kBrickMask, j & kBrickMask, k & kBrickMask)];
    return entry == 0 ? nullptr : cubeList_.data() + (entry - 1);
  }

  // Calls visit(cubes) for each cell holding cubes that the ray passes through within
  // [ray.tmin, min(ray.tmax, tEnd)], in the order the ray enters them; stops early (and
  // returns false) when visit returns false. Cells are stepped through by their planes,
  // so a cell the ray only grazes within rounding may be passed over: the caller tests
  // the cubes themselves.
  template <class Visit>
  bool march(const Ray& ray, float tEnd, Visit&& visit) const;

  size_t memoryBytes() const {
    return brickOf_.size() * sizeof(uint32_t) + cellEntries_.size() * sizeof(uint32_t) +
           cubeList_.size() * sizeof(uint32_t);
  }

 private:
  static constexpr int kBrickShift = 3;
  static constexpr int32_t kBrickMask = (1 << kBrickShift) - 1;
  size_t brickIndex(int32_t bi, int32_t bj, int32_t bk) const {
    return (size_t(bk) * size_t(bricks_[1]) + size_t(bj)) * size_t(bricks_[0]) + size_t(bi);
  }
  static size_t localIndex(int32_t i, int32_t j, int32_t k) {
    return (size_t(k) << (2 * kBrickShift)) | (size_t(j) << kBrickShift) | size_t(i);
  }

  Vec3 origin_{0.0f, 0.0f, 0.0f};
  float spacing_ = 1.0f;
  Bounds3 bounds_;
  std::array<int32_t, 3> cells_{0, 0, 0};
  std::array<int32_t, 3> bricks_{0, 0, 0};
  std::vector<uint32_t> brickOf_;      // per brick: 0 empty, else 1 + its number
  std::vector<uint32_t> cellEntries_;  // 512 per stored brick: 0 empty, else 1 + list offset
  std::vector<uint32_t> cubeList_;     // cube indices grouped by cell, ascending within one
};

template <class Visit>
bool LvoxelLattice::march(const Ray& ray, float tEnd, Visit&& visit) const {
  float t0, t1;
  if (!intersectBox(ray, bounds_.lo, bounds_.hi, t0, t1)) return true;
  t1 = std::min(t1, tEnd);
  if (!(t0 <= t1)) return true;
  const Vec3 start = ray.at(t0);
  std::array<int32_t, 3> cell, step;
  std::array<float, 3> next, inv;
  for (int a = 0; a < 3; ++a) {
    const float f = std::floor((start[a] - origin_[a]) / spacing_);
    cell[a] = static_cast<int32_t>(std::clamp(f, 0.0f, static_cast<float>(cells_[a] - 1)));
    inv[a] = 1.0f / ray.dir[a];
    step[a] = ray.dir[a] > 0.0f ? 1 : ray.dir[a] < 0.0f ? -1 : 0;
  }
  // The distance at which the ray leaves the current cell through axis a's plane.
  auto exitAlong = [&](int a) {
    if (step[a] == 0) return kInf;
    const int32_t plane = cell[a] + (step[a] > 0 ? 1 : 0);
    return (origin_[a] + static_cast<float>(plane) * spacing_ - ray.origin[a]) * inv[a];
  };
  for (int a = 0; a < 3; ++a) next[a] = exitAlong(a);
  for (;;) {
    const uint32_t* cubes = cubesIn(cell[0], cell[1], cell[2]);
    if (cubes && !visit(cubes)) return false;
    const int a = next[0] <= next[1] ? (next[0] <= next[2] ? 0 : 2) : (next[1] <= next[2] ? 1 : 2);
    if (next[a] > t1) return true;
    cell[a] += step[a];
    if (cell[a] < 0 || cell[a] >= cells_[a]) return true;
    next[a] = exitAlong(a);
  }
}

}  // namespace lvox
