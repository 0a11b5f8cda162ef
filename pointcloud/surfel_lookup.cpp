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

SurfelLookup::SurfelLookup(const SurfelSet& surfels, float cell)
    : surfels_(&surfels), cell_(cell > 0.0f ? cell : 1.0f) {
  std::vector<std::pair<uint64_t, uint32_t>> keyed(surfels.size());
  for (size_t i = 0; i < surfels.size(); ++i) {
    const Vec3& p = surfels.position[i];
    keyed[i] = {cellKey(cellOf(p.x), cellOf(p.y), cellOf(p.z)), static_cast<uint32_t>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  order_.resize(keyed.size());
  for (size_t i = 0; i < keyed.size(); ++i) {
    order_[i] = keyed[i].second;
    Range& r = cells_.try_emplace(keyed[i].first, Range{static_cast<uint32_t>(i), 0}).first->second;
    r.end = static_cast<uint32_t>(i + 1);
  }
}

long SurfelLookup::nearest(const Vec3& p, const Vec3& n) const {
  if (!surfels_) return -1;
  const SurfelSet& s = *surfels_;
  const long cx = cellOf(p.x), cy = cellOf(p.y), cz = cellOf(p.z);
  float bestAligned = kInf, bestAny = kInf;
  long aligned = -1, any = -1;
  for (long dx = -1; dx <= 1; ++dx)
    for (long dy = -1; dy <= 1; ++dy)
      for (long dz = -1; dz <= 1; ++dz) {
        const auto it = cells_.find(cellKey(cx + dx, cy + dy, cz + dz));
        if (it == cells_.end()) continue;
        for (uint32_t k = it->second.begin; k < it->second.end; ++k) {
          const uint32_t i = order_[k];
          const Vec3 d = s.position[i] - p;
          // Distance off the surfel's plane counts 4x: a parallel surface close by (the
          // other face of a thin slab) must not win over this surface's own surfels.
          const float off = dot(d, s.normal[i]);
          const float d2 = dot(d, d) + 3.0f * off * off;
          if (d2 < bestAny) {
            bestAny = d2;
            any = i;
          }
          if (d2 < bestAligned && std::abs(dot(s.normal[i], n)) >= 0.5f) {
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
