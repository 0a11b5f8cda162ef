#pragma once
// Nearest surfel to a surface point: the cloud's radiance at a point found by ray tracing
// the real geometry (`"gather_visibility": "rays"`, gather.h). A uniform hash grid of
// cell size `cell`; a query looks at the 27 cells around the point.
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "pointcloud/surfels.h"

namespace lvox {

class SurfelLookup {
 public:
  SurfelLookup() = default;
  SurfelLookup(const SurfelSet& surfels, float cell);

  // The nearest surfel to p whose plane is within 60 degrees of the surface normal n
  // (either side), else the nearest at all; -1 when none is within two cells.
  long nearest(const Vec3& p, const Vec3& n) const;
  bool empty() const { return order_.empty(); }

 private:
  struct Range {
    uint32_t begin, end;
  };
  uint64_t cellKey(long x, long y, long z) const;
  long cellOf(float v) const;

  const SurfelSet* surfels_ = nullptr;
  float cell_ = 1.0f;
  std::vector<uint32_t> order_;  // surfel indices grouped by cell
  std::unordered_map<uint64_t, Range> cells_;
};

}  // namespace lvox
