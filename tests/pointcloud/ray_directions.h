#pragma once
// A gather sink that keeps each ray's direction and nothing else, and where a direction
// lies on the cosine map of an irradiance gather about +z (gatherIrradianceInto).
#include <cmath>
#include <utility>
#include <vector>

#include "src/core/math.h"

namespace lvox::test {

struct RayDirections {
  std::vector<Vec3> dirs;
  void beginRay(const Vec3& d) { dirs.push_back(d); }
  void surfel(uint32_t, bool, const RGB&) {}
  void surfelCluster(uint32_t, const RGB&) {}
  void lvoxel(uint32_t, const RGB&) {}
  void lvoxelCluster(uint32_t, const RGB&) {}
  void addBackground(const RGB&) {}
  void surfaceLight(const RGB&) {}
};

// (u1, u2) = (1 - cos^2, azimuth / 2 pi), each in [0, 1).
inline std::pair<float, float> cosineMapPoint(const Vec3& d) {
  float u2 = std::atan2(d.y, d.x) / (2.0f * kPi);
  if (u2 < 0.0f) u2 += 1.0f;
  return {1.0f - d.z * d.z, u2};
}

}  // namespace lvox::test
