#include "pointcloud/surfel_lookup.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace lvox {

uint64_t SurfelLookup::cellKey(long x, long y, long z) const {
  // 21 bits per axis (offset to keep them non-negative): about 2 million cells per axis.
  const auto u = [](long v) { return static_cast<uint64_t>(v + (1L << 20)) & 0x1fffffull; };
  return (u(x) << 42) | (u(y) << 21) | u(z);
}

long SurfelLookup::cellOf(float v) const { return static_cast<long>(std::floor(v / cell_)); }

SurfelLookup::SurfelLookup(const CloudSurfels& surfels, float cell)
    : surfels_(&surfels), cell_(cell > 0.0f ? cell : 1.0f) {
  const size_t n = surfels.size();
  std::vector<uint64_t> key(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = surfels.position(i);
    key[i] = cellKey(cellOf(p.x), cellOf(p.y), cellOf(p.z));
  }
  order_.resize(n);
  for (size_t i = 0; i < n; ++i) order_[i] = static_cast<uint32_t>(i);
  // By cell, and by index within a cell (the search's tie-breaking order).
  std::sort(order_.begin(), order_.end(),
            [&](uint32_t a, uint32_t b) { return key[a] != key[b] ? key[a] < key[b] : a < b; });
  for (size_t k = 0; k < n; ++k) {
    const uint64_t cellKeyK = key[order_[k]];
    if (keys_.empty() || keys_.back() != cellKeyK) {
      keys_.push_back(cellKeyK);
      cellBegin_.push_back(static_cast<uint32_t>(k));
    }
  }
  cellBegin_.push_back(static_cast<uint32_t>(n));
  keys_.shrink_to_fit();
  cellBegin_.shrink_to_fit();
  // At most half full: short probe sequences.
  size_t capacity = 2;
  while (capacity < 2 * keys_.size()) capacity *= 2;
  slots_.assign(capacity, kEmptySlot);
  for (size_t c = 0; c < keys_.size(); ++c) {
    size_t slot = slotOf(keys_[c], capacity - 1);
    while (slots_[slot] != kEmptySlot) slot = (slot + 1) & (capacity - 1);
    slots_[slot] = static_cast<uint32_t>(c);
  }
}

size_t SurfelLookup::slotOf(uint64_t key, size_t mask) {
  // A 64-bit mix (splitmix64's finaliser): neighbouring cells land far apart.
  key ^= key >> 30;
  key *= 0xbf58476d1ce4e5b9ull;
  key ^= key >> 27;
  key *= 0x94d049bb133111ebull;
  key ^= key >> 31;
  return static_cast<size_t>(key) & mask;
}

uint32_t SurfelLookup::findCell(uint64_t key) const {
  const size_t mask = slots_.size() - 1;
  for (size_t slot = slotOf(key, mask);; slot = (slot + 1) & mask) {
    const uint32_t c = slots_[slot];
    if (c == kEmptySlot || keys_[c] == key) return c;
  }
}

size_t SurfelLookup::memoryBytes() const {
  return order_.capacity() * sizeof(uint32_t) + keys_.capacity() * sizeof(uint64_t) +
         cellBegin_.capacity() * sizeof(uint32_t) + slots_.capacity() * sizeof(uint32_t);
}

namespace {

// The 27 cells around a point's cell, nearest class first (itself, the 6 sharing a face,
// the 12 sharing an edge, the 8 sharing a corner): the first candidates found are likely
// the best, so the cells after them are mostly passed over by their distance bound.
struct CellOffset {
  int8_t dx, dy, dz;
};
constexpr std::array<CellOffset, 27> kCellsNearestFirst = [] {
  std::array<CellOffset, 27> out{};
  int k = 0;
  for (int shared = 0; shared <= 3; ++shared)  // how many axes differ from the centre cell
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz)
          if ((dx != 0) + (dy != 0) + (dz != 0) == shared)
            out[static_cast<size_t>(k++)] = {static_cast<int8_t>(dx), static_cast<int8_t>(dy),
                                             static_cast<int8_t>(dz)};
  return out;
}();

}  // namespace

long SurfelLookup::nearest(const Vec3& p, const Vec3& n) const {
  if (!surfels_ || slots_.empty()) return -1;
  const CloudSurfels& s = *surfels_;
  const long cx = cellOf(p.x), cy = cellOf(p.y), cz = cellOf(p.z);
  // Squared distances from p to the lower and upper face of its cell along each axis: a
  // neighbouring cell's surfels lie at least that far along it.
  const Vec3 lo(p.x - static_cast<float>(cx) * cell_, p.y - static_cast<float>(cy) * cell_,
                p.z - static_cast<float>(cz) * cell_);
  const Vec3 hi = Vec3(cell_) - lo;
  // Less a margin: the cells are binned by floor(v / cell), rounded unlike lo and hi.
  const float margin = 1e-4f * cell_;
  auto gap2 = [margin](int d, float below, float above) {
    const float g = (d < 0 ? below : (d > 0 ? above : 0.0f)) - margin;
    return g > 0.0f ? g * g : 0.0f;
  };
  float bestAligned = kInf, bestAny = kInf;
  long aligned = -1, any = -1;
  // The smaller index wins a tie: the answer does not depend on the order cells are seen.
  auto better = [](float d2, long i, float best, long bestIndex) {
    return d2 < best || (d2 == best && i < bestIndex);
  };
  for (const CellOffset& o : kCellsNearestFirst) {
    // Every metric below is at least the plain squared distance, so a cell whose bound
    // exceeds both bests holds no surfel that could win or tie.
    const float bound = gap2(o.dx, lo.x, hi.x) + gap2(o.dy, lo.y, hi.y) + gap2(o.dz, lo.z, hi.z);
    if (bound > bestAny && bound > bestAligned) continue;
    const uint32_t c = findCell(cellKey(cx + o.dx, cy + o.dy, cz + o.dz));
    if (c == kEmptySlot) continue;
    for (uint32_t k = cellBegin_[c]; k < cellBegin_[c + 1]; ++k) {
      const uint32_t i = order_[k];
      const Vec3 d = s.position(i) - p;
      // In the squared distance, the distance off the surfel's plane counts 4 times: a
      // parallel surface close by (the other face of a thin slab) must not win over
      // this surface's own surfels. The distance behind the surface hit (n faces the
      // gather ray) counts 64 times: there lie the other faces of slabs narrower than
      // the spacing (a slat, a ledge), whose side seen from here is the solid's dark
      // inside (test_buried_surfels.cpp).
      const float off = dot(d, s.normal(i));
      const float behind = std::max(0.0f, -dot(d, n));
      const float d2 = dot(d, d) + 3.0f * off * off + 63.0f * behind * behind;
      if (better(d2, i, bestAny, any)) {
        bestAny = d2;
        any = i;
      }
      if (better(d2, i, bestAligned, aligned) && std::abs(dot(s.normal(i), n)) >= 0.5f) {
        bestAligned = d2;
        aligned = i;
      }
    }
  }
  // Cells farther than 2^20 apart share keys: a candidate from such a cell is not near.
  const float reach2 = 4.0f * cell_ * cell_;
  if (aligned >= 0 && bestAligned <= 4.0f * reach2) return aligned;
  return bestAny <= reach2 ? any : -1;
}

}  // namespace lvox
