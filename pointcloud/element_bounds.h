#pragma once
// Axis-aligned extents of single elements: a disk of radius r and unit normal n spans
// r * sqrt(1 - n_a^2) along axis a; an lvoxel is its cube.
#include <cmath>

#include "pointcloud/lvoxels.h"
#include "pointcloud/ray_element.h"

namespace lvox {

inline Bounds3 diskBounds(const DiskElement& d) {
  const Vec3& n = d.normal;
  const float r = d.radius;
  const Vec3 e(r * std::sqrt(std::max(0.0f, 1.0f - n.x * n.x)),
               r * std::sqrt(std::max(0.0f, 1.0f - n.y * n.y)),
               r * std::sqrt(std::max(0.0f, 1.0f - n.z * n.z)));
  Bounds3 b;
  b.lo = d.position - e;
  b.hi = d.position + e;
  return b;
}

inline Bounds3 lvoxelBounds(const LvoxelSet& l, size_t i) {
  const float h = l.halfSize[i];
  Bounds3 b;
  b.lo = l.position[i] - Vec3(h, h, h);
  b.hi = l.position[i] + Vec3(h, h, h);
  return b;
}

}  // namespace lvox
