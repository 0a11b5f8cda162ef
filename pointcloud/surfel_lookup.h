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
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pointcloud/surfels.h"

namespace lvox {

// The lookup's choice among candidate surfels for a surface point p seen from the side n
// faces: the smallest metric (index breaks ties) whose plane is within 25 degrees of n if
// it lies within four cells, else the smallest at all within two cells, else none. (60
// degrees until stop 49: on Sponza's mouldings a neighbouring facet at 30-60 degrees
// then stood for the hit, with 0.3-0.5 of its light; docs/results.md, stops 30 and 49.)
// In the metric, the squared distance, the distance off the surfel's plane counts 4
// times: a parallel surface close by (the other face of a thin slab) must not win over
// this surface's own surfels. The distance behind the surface hit (n faces the gather ray)
// counts 64 times: there lie the other faces of slabs narrower than the spacing (a slat,
// a ledge), whose side seen from here is the solid's dark inside (test_buried_surfels.cpp).
class NearestSurfelChoice {
 public:
  static constexpr float kAligned = 0.9f;  // |cos| of the planes' angle: 25 degrees
  NearestSurfelChoice(const CloudSurfels& surfels, const Vec3& p, const Vec3& n)
      : s_(surfels), p_(p), n_(n) {}
  void consider(uint32_t i) {
    const Vec3 d = s_.position(i) - p_;
    const float off = dot(d, s_.normal(i));
    const float behind = std::max(0.0f, -dot(d, n_));
    const float d2 = dot(d, d) + 3.0f * off * off + 63.0f * behind * behind;
    if (better(d2, i, bestAny_, any_)) {
      bestAny_ = d2;
      any_ = i;
    }
    if (better(d2, i, bestAligned_, aligned_) && std::abs(dot(s_.normal(i), n_)) >= kAligned) {
      bestAligned_ = d2;
      aligned_ = i;
    }
  }
  // False when no surfel whose metric is at least `bound` could change the choice (the
  // metric is at least the plain squared distance).
  bool couldImprove(float bound) const { return bound <= bestAny_ || bound <= bestAligned_; }
  long result(float cell) const {
    const float reach2 = 4.0f * cell * cell;
    if (aligned_ >= 0 && bestAligned_ <= 4.0f * reach2) return aligned_;
    return bestAny_ <= reach2 ? any_ : -1;
  }

 private:
  // The smaller index wins a tie: the answer does not depend on the order of candidates.
  static bool better(float d2, long i, float best, long bestIndex) {
    return d2 < best || (d2 == best && i < bestIndex);
  }
  const CloudSurfels& s_;
  Vec3 p_, n_;
  float bestAligned_ = kInf, bestAny_ = kInf;
  long aligned_ = -1, any_ = -1;
};

class SurfelLookup {
 public:
  SurfelLookup() = default;
  SurfelLookup(const CloudSurfels& surfels, float cell);

  // The nearest surfel to p whose plane is within 25 degrees of the surface normal n
  // (either side), else the nearest at all; -1 when none is within two cells. n faces the
  // side the point is seen from: distance behind the surface counts most.
  long nearest(const Vec3& p, const Vec3& n) const;
  bool empty() const { return order_.empty(); }
  float cell() const { return cell_; }
  const CloudSurfels* surfels() const { return surfels_; }
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
