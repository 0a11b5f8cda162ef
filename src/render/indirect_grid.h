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
//
// Where the valid grid points lie on one side of the sample (along a concave corner, next
// to a silhouette) their mean stands for the light a few pixels away, not at the sample:
// irradiance that falls towards a corner came out too bright along it and irradiance that
// rises towards a sunlit one too dark. The linear fit (GatherFit::kLinear, the default)
// evaluates the plane that fits the points in the weighted least-squares sense at the
// sample instead (local linear regression): exact for irradiance linear across the
// screen, on either side of an edge. Where the points surround the sample it is their
// weighted mean, as the constant fit.
#include <vector>

#include "pointcloud/gather.h"
#include "pointcloud/pointcloud_settings.h"
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
               int spacing, float filterRadius, GatherFit fit, uint64_t seed,
               Collective& team = singleProcess());

  // The grid points over a width x height image at that spacing (the constructor's).
  static size_t pointsFor(int width, int height, int spacing);

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
  // Grid points along `pixels` pixels: pixels 0, s, 2s, ... and one past the last.
  static long pointsAlong(int pixels, int spacing);
  const Point& at(long i, long j) const { return points_[static_cast<size_t>(j * nx_ + i)]; }
  // f(point, tent weight, offset along x, along y in grid spacings) for every grid point
  // within the tent about (u, v) that is valid for the hit.
  template <class F>
  void forEachValid(float u, float v, const SurfaceHit& hit, F&& f) const;

  int spacing_ = 1;
  float filterRadius_ = 1.0f;  // tent half-width in grid spacings; 1: bilinear
  GatherFit fit_ = GatherFit::kLinear;
  long nx_ = 0, ny_ = 0;
  std::vector<Point> points_;
};

}  // namespace lvox
