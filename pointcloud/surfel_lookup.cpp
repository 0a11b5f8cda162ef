#include "pointcloud/surfel_lookup.h"

#include <algorithm>
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

long SurfelLookup::nearest(const Vec3& p, const Vec3& n) const {
  if (!surfels_ || slots_.empty()) return -1;
  const CloudSurfels& s = *surfels_;
  const long cx = cellOf(p.x), cy = cellOf(p.y), cz = cellOf(p.z);
  float bestAligned = kInf, bestAny = kInf;
  long aligned = -1, any = -1;
  for (long dx = -1; dx <= 1; ++dx)
    for (long dy = -1; dy <= 1; ++dy)
      for (long dz = -1; dz <= 1; ++dz) {
        const uint32_t c = findCell(cellKey(cx + dx, cy + dy, cz + dz));
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
          if (d2 < bestAny) {
            bestAny = d2;
            any = i;
          }
          if (d2 < bestAligned && std::abs(dot(s.normal(i), n)) >= 0.5f) {
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
