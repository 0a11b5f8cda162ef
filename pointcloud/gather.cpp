#include "pointcloud/gather.h"

#include <cmath>

namespace lvox {

RGB gatherRay(const PointCloud& cloud, const Ray& ray, const GatherOptions& options,
              TraversalScratch& scratch) {
  RadianceSink sink{cloud, options.background};
  traceGatherRay(cloud, ray, options, 1.0f, scratch, sink);
  return sink.radiance;
}

void strataGrid(int n, int& rows, int& cols) {
  n = std::max(n, 1);
  rows = static_cast<int>(std::sqrt(static_cast<double>(n)));
  while (n % rows != 0) --rows;
  cols = n / rows;
}

int nearFieldRaysPerRay(const GatherOptions& options) {
  const int samples = std::max(options.samples, 1);
  if (!(options.nearReach > 0.0f) || options.nearSamples <= samples) return 0;
  return (options.nearSamples + samples - 1) / samples - 1;
}

RGB gatherIrradiance(const PointCloud& cloud, const Vec3& p, const Vec3& n,
                     const GatherOptions& options, Rng& rng, TraversalScratch& scratch) {
  RadianceSink sink{cloud, options.background};
  gatherIrradianceInto(cloud, p, n, options, rng, scratch, sink);
  return sink.radiance;
}

IrradianceParts gatherIrradianceParts(const PointCloud& cloud, const Vec3& p, const Vec3& n,
                                      const GatherOptions& options, Rng& rng,
                                      TraversalScratch& scratch, const Vec3* shading) {
  RadianceSink sink{cloud, RGB(0.0f)};
  gatherIrradianceInto(cloud, p, n, options, rng, scratch, sink, shading);
  return {sink.radiance, sink.escaped * options.background};
}

RGB gatherIrradiance(const PointCloud& cloud, const Vec3& p, const Vec3& n,
                     const GatherOptions& options, Rng& rng) {
  TraversalScratch scratch;
  return gatherIrradiance(cloud, p, n, options, rng, scratch);
}

}  // namespace lvox
