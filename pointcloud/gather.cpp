#include "pointcloud/gather.h"

#include <cmath>

namespace lvox {

RGB gatherRay(const PointCloud& cloud, const Ray& ray, const GatherOptions& options,
              TraversalScratch& scratch) {
  GatherRayVisitor visitor{cloud, options.minTransmittance};
  traverse(cloud, ray, visitor,
           TraversalOptions{options.maxSolidAngle, options.maxLvoxelSolidAngle}, scratch);
  if (!visitor.opaqueHit && maxComponent(visitor.transmittance) >= options.minTransmittance)
    visitor.radiance += visitor.transmittance * options.background;
  return visitor.radiance;
}

void strataGrid(int n, int& rows, int& cols) {
  n = std::max(n, 1);
  rows = static_cast<int>(std::sqrt(static_cast<double>(n)));
  while (n % rows != 0) --rows;
  cols = n / rows;
}

RGB gatherIrradiance(const PointCloud& cloud, const Vec3& p, const Vec3& n,
                     const GatherOptions& options, Rng& rng, TraversalScratch& scratch) {
  int rows, cols;
  strataGrid(options.samples, rows, cols);
  const Frame frame(n);
  RGB sum(0.0f);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const float u1 = (static_cast<float>(r) + rng.uniform()) / static_cast<float>(rows);
      const float u2 = (static_cast<float>(c) + rng.uniform()) / static_cast<float>(cols);
      const Ray ray{p, frame.toWorld(cosineHemisphere(u1, u2)), options.rayOffset, kInf};
      sum += gatherRay(cloud, ray, options, scratch);
    }
  // Cosine-weighted pdf cos/pi: E = integral L cos dw = pi * mean(L).
  return sum * (kPi / static_cast<float>(rows * cols));
}

RGB gatherIrradiance(const PointCloud& cloud, const Vec3& p, const Vec3& n,
                     const GatherOptions& options, Rng& rng) {
  TraversalScratch scratch;
  return gatherIrradiance(cloud, p, n, options, rng, scratch);
}

}  // namespace lvox
