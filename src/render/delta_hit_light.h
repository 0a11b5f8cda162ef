#pragma once
// The point, spot and directional lights' light at pcb's traced gather hits
// (pointcloud/gather.h, SurfaceHitLight): exact shadow rays, and the transmittance
// through the media or through the lvoxels' cubes, at the hit itself, with the albedo
// under it. With `"gather_visibility": "rays"` the surfels then cache the other lights'
// light only (docs/pcb.md: a delta light's shadow edges are sharper than the surfel
// spacing).
#include <tbb/combinable.h>

#include <cstdint>

#include "pointcloud/gather.h"
#include "src/render/render_context.h"
#include "src/render/volume_transport.h"

namespace lvox {

class DeltaHitLight final : public SurfaceHitLight {
 public:
  // `reducedShadows`: transmittance through directional lvoxels' media without the forward
  // peaks, as every shadow ray of the cloud's light (PointBasedCache::reducedShadows).
  // `cubes`: the cloud whose lvoxels' cubes the shadow rays cross instead of the media
  // (pointcloud.indirect_shadow_media "cubes"; they hold the reduced media where asked).
  DeltaHitLight(const RenderContext& ctx, const VolumeTransport& volume, bool reducedShadows,
                const PointCloud* cubes = nullptr)
      : ctx_(ctx), volume_(volume), reducedShadows_(reducedShadows), cubes_(cubes) {}

  RGB reflected(const SurfaceHit& hit) const override;
  RGB reflected(const Vec3& p, const Vec3& n, const RGB& albedo) const override;

  struct Counts {
    uint64_t shadowRays = 0;
    rte::SolveCounts solve;
  };
  // Summed over the threads since construction.
  Counts total() const;
  // The calling thread's own since construction: a camera sample's gather takes the
  // difference, to count its shadow rays and charge its evaluations to the work budget.
  Counts threadCounts() const { return counts_.local(); }

 private:
  RGB reflectedAt(const SurfaceHit& hit, const RGB& albedo) const;

  const RenderContext& ctx_;
  const VolumeTransport& volume_;
  bool reducedShadows_;
  const PointCloud* cubes_;
  mutable tbb::combinable<Counts> counts_;
};

}  // namespace lvox
