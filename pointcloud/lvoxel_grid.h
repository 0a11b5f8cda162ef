#pragma once
// The one grid lvoxels live on: cubes of side `spacing` from `origin`, `cells` per axis,
// covering the bounds the grid was made for. The lvoxels of every medium of a scene share
// one grid, so overlapping media share cells, and the light cached on them.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "src/core/math.h"

namespace lvox {

struct LvoxelGrid {
  Vec3 origin{0.0f, 0.0f, 0.0f};
  float spacing = 1.0f;
  std::array<long, 3> cells{0, 0, 0};

  // The smallest grid from b.lo that covers b (at least one cell per axis).
  static LvoxelGrid covering(const Bounds3& b, float spacing) {
    LvoxelGrid g{b.lo, spacing, {}};
    for (int a = 0; a < 3; ++a)
      g.cells[a] = std::max(1L, static_cast<long>(std::ceil((b.hi[a] - b.lo[a]) / spacing)));
    return g;
  }
  // In double: checked against a budget before anything is allocated.
  double cellCount() const {
    return static_cast<double>(cells[0]) * static_cast<double>(cells[1]) *
           static_cast<double>(cells[2]);
  }
  size_t index(long i, long j, long k) const {
    return static_cast<size_t>((k * cells[1] + j) * cells[0] + i);
  }
  // Index of the cell containing p, or -1 outside the grid.
  long cellOf(const Vec3& p) const {
    long c[3];
    for (int a = 0; a < 3; ++a) {
      c[a] = static_cast<long>(std::floor((p[a] - origin[a]) / spacing));
      if (c[a] < 0 || c[a] >= cells[a]) return -1;
    }
    return static_cast<long>(index(c[0], c[1], c[2]));
  }
  // The lower corner of cell (i, j, k).
  Vec3 cellLow(long i, long j, long k) const {
    return origin +
           Vec3(static_cast<float>(i), static_cast<float>(j), static_cast<float>(k)) * spacing;
  }
  Vec3 centre(long cell) const {
    const long k = cell / (cells[0] * cells[1]);
    const long j = (cell / cells[0]) % cells[1];
    const long i = cell % cells[0];
    return origin + Vec3(static_cast<float>(i) + 0.5f, static_cast<float>(j) + 0.5f,
                         static_cast<float>(k) + 0.5f) *
                        spacing;
  }
  bool operator==(const LvoxelGrid&) const = default;
};

}  // namespace lvox
