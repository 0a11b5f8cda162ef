#pragma once
// Emitters seen directly, and what they light beside them, sampled more finely than the
// camera samples (pcb modes).
//
// An emitter is far brighter than what surrounds it, so a pixel its edge crosses takes a
// value between the two in proportion to how much of it the emitter covers, and a few
// camera samples guess that share coarsely: on the closed room at 4 spp the lamp and the
// pixels beside it held 1.4 % of the image's 3.4 % error against a converged reference
// (docs/results.md, "Emitters seen directly"). A camera sample of pcb costs a volume solve,
// gathers and shadow rays, while what an emitter adds is one ray and the transmittance in
// front of it. So in the pixels an emitter's edge may cross, each camera sample leaves its
// own ray's emission out and takes the mean of `raysPerSample` rays stratified over the
// pixel instead: the same integral over the pixel, estimated with more rays. Elsewhere the
// camera ray's own emission stands, as before: inside an emitter it is exact, and an
// emitter smaller than a pixel that the probes below miss is still found by it, as
// coarsely.
//
// The surfaces right beside an emitter are the next brightest thing in those pixels, and
// their light changes as fast as the distance to the emitter does (a wall 2 cm behind a
// lamp is lit many times more at its edge than a pixel further on). So the same rays take
// the light those surfaces reflect straight from the lights too (surfaceDirect), in place
// of the camera ray's, each with a quarter of a camera sample's area-light samples
// (edgeLightSamples): the rays of one camera sample take 4 times its light samples, and
// the pixel's coverage is stratified as the emitter's. On the lamp hall 1 sample per ray
// (as many in all as the camera ray's) took 40 % of the gain, a quarter kept nearly all of
// what a whole camera sample's per ray gives, at a fifth of its shadow rays (docs/
// results.md, stop 44). What reaches those surfaces through the cloud (the gathers) and
// the media in front stay the camera ray's.
//
// Not the environment seen past a silhouette. The camera ray's sample of such a pixel is
// the surface's radiance L_s or the sky's L_e, whose difference is what its coverage noise
// multiplies; with the sky taken from rays of its own the surface part keeps its coverage
// noise but alone, times L_s. That is less noise only where L_e > 2 L_s: true of a lamp
// against what it lights nearly always, not of a sky beside sunlit walls (the open town's
// silhouettes came out 1.18 -> 1.21 % from its reference when the sky had them too).
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "src/core/rng.h"
#include "src/render/light_set.h"
#include "src/render/render_context.h"
#include "src/render/surface_albedo.h"
#include "src/render/surface_direct.h"

namespace lvox {

// Area-light samples per ray of an edge pixel: a quarter of a camera sample's, at least 1.
inline int edgeLightSamples(int areaLightSamples) { return std::max(1, areaLightSamples / 4); }

class EmitterPixels {
 public:
  // Probes the pixels' corners and centres with one ray each. A pixel is on an emitter's
  // edge when its probes (its corners and centre, its 8 neighbours' centres) meet an
  // emitter and do not all meet the same: one of them meets something else.
  // Parallel and deterministic.
  EmitterPixels(const RenderContext& ctx, int raysPerSample);

  // How many pixels are on an emitter's edge, and whether (x, y) is one of them.
  size_t pixelCount() const { return count_; }
  bool covers(int x, int y) const {
    return !edge_.empty() &&
           edge_[static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x)];
  }

  // What the camera sees straight from the lights through pixel (x, y): the mean over
  // raysPerSample rays, one jittered in each of as many strata of the pixel, of what each
  // meets first, times cameraTransmittance(ray) (the media in front of it, ray.tmax at the
  // surface): an emitter's emission, or the light a surface reflects from the lights of
  // `subset` (surfaceDirect with lightSamples() samples per area light, its shadow rays
  // through shadowTransmittance). `rays` counts the pixel rays, `shadowRays` theirs.
  struct Seen {
    RGB emission{0.0f};
    RGB direct{0.0f};
  };
  template <class CameraTransmittance, class ShadowTransmittance>
  Seen seen(const RenderContext& ctx, int x, int y, Rng& rng,
            CameraTransmittance&& cameraTransmittance, ShadowTransmittance&& shadowTransmittance,
            const LightSubset& subset, uint64_t& rays, uint64_t& shadowRays) const;
  // Area-light samples per ray (edgeLightSamples of render.area_light_samples).
  int lightSamples() const { return lightSamples_; }

 private:
  int raysPerSample_ = 1;
  int rows_ = 1, cols_ = 1;  // the strata: rows_ x cols_ == raysPerSample_
  int lightSamples_ = 1;
  std::unique_ptr<const LightSet> lights_;  // with lightSamples_ per area light
  int width_ = 0;
  std::vector<char> edge_;  // per pixel: on an emitter's edge
  size_t count_ = 0;
};

template <class CameraTransmittance, class ShadowTransmittance>
EmitterPixels::Seen EmitterPixels::seen(const RenderContext& ctx, int x, int y, Rng& rng,
                                        CameraTransmittance&& cameraTransmittance,
                                        ShadowTransmittance&& shadowTransmittance,
                                        const LightSubset& subset, uint64_t& rays,
                                        uint64_t& shadowRays) const {
  const World& world = ctx.world;
  const RenderContext withSamples{world, ctx.settings, ctx.tracer, *lights_, ctx.budget};
  Seen sum;
  for (int r = 0; r < rows_; ++r)
    for (int c = 0; c < cols_; ++c) {
      const float px = static_cast<float>(x) +
                       (static_cast<float>(c) + rng.uniform()) / static_cast<float>(cols_);
      const float py = static_cast<float>(y) +
                       (static_cast<float>(r) + rng.uniform()) / static_cast<float>(rows_);
      Ray ray = world.camera.generateRay(px, py);
      SurfaceHit hit;
      ++rays;
      if (!ctx.tracer.intersect(ray, hit)) continue;
      const Material& m = world.materials[world.mesh.triangleMaterial[hit.triangle]];
      const RGB albedo = cameraHitAlbedo(ctx, m, ray, hit);
      // A black surface (a lamp's) reflects nothing: no shadow rays for it.
      const RGB reflected = isBlack(albedo)
                                ? RGB(0.0f)
                                : surfaceDirect(withSamples, hit, albedo, rng, shadowTransmittance,
                                                shadowRays, subset);
      ray.tmax = hit.t;
      const RGB throughMedia = cameraTransmittance(ray);
      sum.emission += m.emission * throughMedia;
      sum.direct += reflected * throughMedia;
    }
  const float n = static_cast<float>(rows_ * cols_);
  return {sum.emission / n, sum.direct / n};
}

}  // namespace lvox
