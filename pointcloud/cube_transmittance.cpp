#include "pointcloud/cube_transmittance.h"

#include <algorithm>
#include <cmath>

namespace lvox {
namespace {

// Sums the optical depth of the cubes and clusters a ray meets.
struct OpticalDepthSum {
  const PointCloud& cloud;
  RGB tau{0.0f, 0.0f, 0.0f};
  bool transparent() const { return std::min({tau.x, tau.y, tau.z}) < kOpaqueDepth; }
  void surfel(uint32_t, float, bool) {}
  bool surfelCluster(uint32_t, float, float) { return true; }
  bool lvoxel(uint32_t i, float t0, float t1) {
    tau += cloud.lvoxels().sigmaT(i) * (t1 - t0);
    return transparent();
  }
  bool lvoxelCluster(uint32_t n, float t0, float t1) {
    tau += cloud.lvoxelClusters()[n].sigmaT * (t1 - t0);
    return transparent();
  }
};

}  // namespace

RGB cubeTransmittance(const PointCloud& cloud, const Ray& ray, TraversalScratch& scratch,
                      const TraversalOptions& options) {
  TraversalOptions lvoxelsOnly = options;
  lvoxelsOnly.surfels = false;
  OpticalDepthSum sum{cloud};
  traverse(cloud, ray, sum, lvoxelsOnly, scratch);
  return RGB(std::exp(-sum.tau.x), std::exp(-sum.tau.y), std::exp(-sum.tau.z));
}

}  // namespace lvox
