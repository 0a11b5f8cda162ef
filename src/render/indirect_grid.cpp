#include "src/render/indirect_grid.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace lvox {
namespace {

constexpr float kMinNormalCosine = 0.9f;   // about 25 degrees
constexpr float kMaxPlaneDistance = 2.0f;  // in pixel footprints at the grid point
constexpr float kMaxReach = 2.0f;          // in grid spacings, along the surface
// The linear fit's slopes are regularised by this share of the variance of a whole tent's
// offsets (r^2 / 6 along each axis for half-width r): where the points hardly spread along
// a direction (one row of them, or two with almost all the weight on one) a slope would
// multiply their noise by the distance over that spread. Where they spread as a whole
// tent does, the slopes keep 10 / 11 of their size; on one side of an edge (half a tent,
// a third of the spread) about 3 / 4.
constexpr double kSlopeRidge = 0.1;

}  // namespace

IndirectGrid::IndirectGrid(const RenderContext& ctx, const PointCloud& cloud,
                           const GatherOptions& options, int spacing, float filterRadius,
                           GatherFit fit, uint64_t seed, Collective& team)
    : spacing_(std::max(1, spacing)), filterRadius_(std::max(1.0f, filterRadius)), fit_(fit) {
  const Camera& camera = ctx.world.camera;
  // Grid points at the centres of pixels 0, s, 2s, ... plus one past the last pixel, so
  // every pixel lies between grid points.
  nx_ = pointsAlong(camera.width, spacing_);
  ny_ = pointsAlong(camera.height, spacing_);
  points_.resize(static_cast<size_t>(nx_ * ny_));
  // Per point the irradiance from the cloud, then from the background.
  std::vector<RGB> irradiance(2 * points_.size(), RGB(0.0f));
  std::vector<char> hits(points_.size(), 0);
  const long rank = team.rank(), ranks = team.size();
  tbb::parallel_for(long(0), ny_, [&](long j) {
    TraversalScratch scratch;
    for (long i = 0; i < nx_; ++i) {
      Point& pt = points_[static_cast<size_t>(j * nx_ + i)];
      const float px = static_cast<float>(i * spacing_) + 0.5f;
      const float py = static_cast<float>(j * spacing_) + 0.5f;
      const Ray ray = camera.generateRay(px, py);
      SurfaceHit hit;
      if (!ctx.tracer.intersect(ray, hit)) continue;
      const Ray next = camera.generateRay(px + 1.0f, py);
      pt.position = hit.point;
      pt.normal = hit.normal;
      // One pixel's width at the hit distance (the angle between neighbouring pixel rays).
      pt.footprint = hit.t * length(next.dir - ray.dir) / std::max(dot(next.dir, ray.dir), 1e-3f);
      // Neighbouring grid points on an oblique surface are further apart in the world.
      pt.reach = kMaxReach * static_cast<float>(spacing_) * pt.footprint /
                 std::max(std::abs(dot(ray.dir, hit.normal)), 0.25f);
      hits[static_cast<size_t>(j * nx_ + i)] = 1;
      if (j % ranks != rank) continue;  // another rank's row
      Rng rng(seed ^ 0x9a7e5u, static_cast<uint64_t>(j * nx_ + i));
      // Each point of a 2 x 2 block samples its own quarter of every stratum: the filter
      // averages neighbouring points, whose directions then stratify the hemisphere
      // four times as finely between them (interleaved sampling; docs/results.md).
      GatherOptions quartered = options;
      quartered.quarter = static_cast<int>((i & 1) | ((j & 1) << 1));
      const IrradianceParts parts = gatherIrradianceParts(cloud, hit.point, hit.normal, quartered,
                                                          rng, scratch, &hit.shading);
      irradiance[2 * static_cast<size_t>(j * nx_ + i)] = parts.cloud;
      irradiance[2 * static_cast<size_t>(j * nx_ + i) + 1] = parts.background;
    }
  });
  team.sum(floatsOf(irradiance));  // each point's from its row's rank, zeros from the others
  for (size_t k = 0; k < points_.size(); ++k) {
    points_[k].irradiance = {irradiance[2 * k], irradiance[2 * k + 1]};
    points_[k].valid = hits[k] && isFinite(irradiance[2 * k]) && isFinite(irradiance[2 * k + 1]);
  }
}

long IndirectGrid::pointsAlong(int pixels, int spacing) {
  return (pixels - 1) / std::max(1, spacing) + 2;
}

size_t IndirectGrid::pointsFor(int width, int height, int spacing) {
  return static_cast<size_t>(pointsAlong(width, spacing) * pointsAlong(height, spacing));
}

template <class F>
void IndirectGrid::forEachValid(float u, float v, const SurfaceHit& hit, F&& f) const {
  const float radius = filterRadius_;
  const long i0 = std::max(static_cast<long>(std::floor(u - radius)) + 1, 0L);
  const long i1 = std::min(static_cast<long>(std::ceil(u + radius)) - 1, nx_ - 1);
  const long j0 = std::max(static_cast<long>(std::floor(v - radius)) + 1, 0L);
  const long j1 = std::min(static_cast<long>(std::ceil(v + radius)) - 1, ny_ - 1);
  for (long j = j0; j <= j1; ++j)
    for (long i = i0; i <= i1; ++i) {
      const float du = static_cast<float>(i) - u, dv = static_cast<float>(j) - v;
      const float w = std::max(0.0f, 1.0f - std::abs(du) / radius) *
                      std::max(0.0f, 1.0f - std::abs(dv) / radius);
      if (!(w > 0.0f)) continue;
      const Point& pt = at(i, j);
      if (!pt.valid || dot(pt.normal, hit.normal) < kMinNormalCosine) continue;
      const Vec3 d = pt.position - hit.point;
      if (std::abs(dot(d, hit.normal)) > kMaxPlaneDistance * pt.footprint ||
          length(d) > pt.reach * radius)
        continue;
      f(pt, w, du, dv);
    }
}

bool IndirectGrid::lookup(float px, float py, const SurfaceHit& hit,
                          IrradianceParts& irradiance) const {
  const float u = (px - 0.5f) / static_cast<float>(spacing_);
  const float v = (py - 0.5f) / static_cast<float>(spacing_);
  // The tent's moments over the valid points: weight, mean offset, covariance.
  double s0 = 0.0, su = 0.0, sv = 0.0, suu = 0.0, suv = 0.0, svv = 0.0;
  forEachValid(u, v, hit, [&](const Point&, float w, float du, float dv) {
    s0 += w;
    su += w * du;
    sv += w * dv;
    suu += w * du * du;
    suv += w * du * dv;
    svv += w * dv * dv;
  });
  // A sample right next to rejected points would lean on one far point alone.
  if (s0 < 0.05) return false;
  const double mu = su / s0, mv = sv / s0;
  // The plane fitted by weighted least squares, at the sample (offset 0): the weighted
  // mean plus its slopes times (0 - mean offset), slopes = covariance^-1 x the weighted
  // covariance of offset and irradiance. That makes each point's weight
  // w / s0 x (1 + (offset - mean offset) . g) with g = -covariance^-1 x mean offset:
  // independent of the irradiance, so both parts and all colours share it.
  double gu = 0.0, gv = 0.0;
  if (fit_ == GatherFit::kLinear) {
    const double ridge = kSlopeRidge * filterRadius_ * filterRadius_ / 6.0;
    const double cuu = suu / s0 - mu * mu + ridge, cvv = svv / s0 - mv * mv + ridge;
    const double cuv = suv / s0 - mu * mv;
    const double det = cuu * cvv - cuv * cuv;  // > 0: positive semi-definite plus the ridge
    gu = -(cvv * mu - cuv * mv) / det;
    gv = -(cuu * mv - cuv * mu) / det;
  }
  IrradianceParts sum;
  forEachValid(u, v, hit, [&](const Point& pt, float w, float du, float dv) {
    const auto k = static_cast<float>(w / s0 * (1.0 + (du - mu) * gu + (dv - mv) * gv));
    sum.cloud += pt.irradiance.cloud * k;
    sum.background += pt.irradiance.background * k;
  });
  // Extrapolated past the points, a plane through noisy values can dip below zero.
  irradiance = {nonNegative(sum.cloud), nonNegative(sum.background)};
  return true;
}

}  // namespace lvox
