#pragma once
// Nearest surfel to a surface point: the cloud's radiance at a point found by ray tracing
// the real geometry (`"gather_visibility": "rays"`, gather.h). A uniform hash grid of
// cell size `cell`; a query looks at the 27 cells around the point. The occupied cells are
// kept sorted by key with an open-addressing index over them: about 20 bytes per cell,
// against 40 and more for a node-based hash map (issue 13: bytes per element at millions
// of surfels).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pointcloud/surfels.h"

namespace lvox {

class SurfelLookup {
 public:
  SurfelLookup() = default;
  SurfelLookup(const CloudSurfels& surfels, float cell);

  // The nearest surfel to p whose plane is within 60 degrees of the surface normal n
  // (either side), else the nearest at all; -1 when none is within two cells. n faces the
  // side the point is seen from: distance behind the surface counts most.
  long nearest(const Vec3& p, const Vec3& n) const;
  bool empty() const { return order_.empty(); }
  size_t memoryBytes() const;

 private:
  static constexpr uint32_t kEmptySlot = ~0u;
  uint64_t cellKey(long x, long y, long z) const;
  long cellOf(float v) const;
  // Index into keys_ of the cell with this key, or kEmptySlot.
  uint32_t findCell(uint64_t key) const;
  static size_t slotOf(uint64_t key, size_t mask);

  const CloudSurfels* surfels_ = nullptr;
  float cell_ = 1.0f;
  std::vector<uint32_t> order_;      // surfel indices grouped by cell, ascending in a cell
  std::vector<uint64_t> keys_;       // occupied cells, ascending
  std::vector<uint32_t> cellBegin_;  // cell c's surfels are order_[cellBegin_[c], cellBegin_[c+1])
  std::vector<uint32_t> slots_;      // open addressing (linear probing): cell index or empty
};

}  // namespace lvox
