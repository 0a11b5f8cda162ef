#pragma once
// Final gathers at a reduced screen-space rate (pcb modes): the point cloud is gathered
// at camera hits on a grid of pixels every `spacing` pixels, and each camera sample
// filters the irradiance of the grid points around it, the cloud's and the background's
// (the sky, when the gathers carry it) apart. A grid point
// only counts where it sees the same surface: normal within ~25 degrees and the hit
// point within a few pixel footprints of the sample's plane (irradiance caching's
// validity test, Ward 1988, in screen space). Samples with no valid grid point gather
// for themselves. Indirect light is smooth on surfaces, so this trades a little blur of
// contact shading for an order of magnitude fewer gather rays.
#include <vector>

#include "pointcloud/gather.h"
#include "src/core/collective.h"
#include "src/render/render_context.h"

namespace lvox {

class IndirectGrid {
 public:
  IndirectGrid() = default;
  // Gathers `options.samples` rays at every grid point (parallel, deterministic). Over
  // several ranks each gathers the rows j with j % size == rank and the sums over the
  // ranks give every rank the grid one process gathers.
  IndirectGrid(const RenderContext& ctx, const PointCloud& cloud, const GatherOptions& options,
               int spacing, float filterRadius, uint64_t seed, Collective& team = singleProcess());

  bool empty() const { return points_.empty(); }
  size_t pointCount() const { return points_.size(); }
  // Irradiance at the camera sample at image position (px, py) whose hit is `hit`, split as
  // gathered (from the cloud, from the background); false when no grid point around it is
  // valid for that hit.
  bool lookup(float px, float py, const SurfaceHit& hit, IrradianceParts& irradiance) const;

 private:
  struct Point {
    Vec3 position, normal;
    IrradianceParts irradiance;
    float footprint = 0.0f;  // world size of one pixel at the hit
    float reach = 0.0f;      // how far along the surface the point may be used
    bool valid = false;
  };
  const Point& at(long i, long j) const { return points_[static_cast<size_t>(j * nx_ + i)]; }

  int spacing_ = 1;
  float filterRadius_ = 1.0f;  // tent half-width in grid spacings; 1: bilinear
  long nx_ = 0, ny_ = 0;
  std::vector<Point> points_;
};

}  // namespace lvox
