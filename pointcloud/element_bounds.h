#pragma once
// Axis-aligned extents of single elements: a disk of radius r and unit normal n spans
// r * sqrt(1 - n_a^2) along axis a; an lvoxel is its cube.
#include <cmath>

#include "pointcloud/lvoxels.h"
#include "pointcloud/surfels.h"

namespace lvox {

inline Bounds3 surfelBounds(const SurfelSet& s, size_t i) {
  const Vec3& n = s.normal[i];
  const float r = s.radius[i];
  const Vec3 e(r * std::sqrt(std::max(0.0f, 1.0f - n.x * n.x)),
               r * std::sqrt(std::max(0.0f, 1.0f - n.y * n.y)),
               r * std::sqrt(std::max(0.0f, 1.0f - n.z * n.z)));
  Bounds3 b;
  b.lo = s.position[i] - e;
  b.hi = s.position[i] + e;
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
