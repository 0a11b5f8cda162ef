#pragma once
// Nearest surfel to a surface point: the cloud's radiance at a point found by ray tracing
// the real geometry (`"gather_visibility": "rays"`, gather.h). A uniform grid of cell size
// `cell`; a query looks at the 27 cells around the point.
//
// The grid is held in blocks of 4 x 4 x 4 cells: an open-addressing table of the occupied
// blocks, each with a 64-bit mask of its occupied cells and the index of its first one, and
// the occupied cells of a block stored one after another. The cells a query reads mostly
// lie in one or two blocks, so it waits on one or two table slots where a table of single
// cells made it wait on a slot and a key per cell (issue 13, item 4: the lookup was most of
// a traced gather ray's time). About 12 bytes per surfel on a surface, against 26 for a
// table of single cells (item 6: 33 MB against 73 MB for the 2.8 M surfels of the real
// Sponza at Gibson's density).
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
  struct Block {
    uint64_t key = kEmptyKey;
    uint64_t occupied = 0;   // bit b: the block's cell b holds surfels (cellBit)
    uint32_t firstCell = 0;  // index into cellBegin_ of its lowest occupied cell
  };
  static constexpr uint64_t kEmptyKey = ~0ull;  // keys use 63 bits: never a block's key

  static uint64_t blockKey(long x, long y, long z);  // of the block holding cell (x, y, z)
  static unsigned cellBit(long x, long y, long z);   // that cell's place in its block
  long cellOf(float v) const;
  // The block with this key, or nullptr when none of its cells holds a surfel.
  const Block* findBlock(uint64_t key) const;
  static size_t slotOf(uint64_t key, size_t mask);

  const CloudSurfels* surfels_ = nullptr;
  float cell_ = 1.0f;
  std::vector<uint32_t> order_;      // surfel indices grouped by cell, ascending in a cell
  std::vector<uint32_t> cellBegin_;  // cell c's surfels are order_[cellBegin_[c], cellBegin_[c+1])
  std::vector<Block> blocks_;        // open addressing (linear probing), at most half full
};

}  // namespace lvox
