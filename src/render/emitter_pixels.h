#pragma once
// Emitters seen directly, sampled more finely than the camera samples (pcb modes).
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
// Not the environment seen past a silhouette. The camera ray's sample of such a pixel is
// the surface's radiance L_s or the sky's L_e, whose difference is what its coverage noise
// multiplies; with the sky taken from rays of its own the surface part keeps its coverage
// noise but alone, times L_s. That is less noise only where L_e > 2 L_s: true of a lamp
// against what it lights nearly always, not of a sky beside sunlit walls (the open town's
// silhouettes came out 1.18 -> 1.21 % from its reference when the sky had them too).
#include <cstdint>
#include <vector>

#include "src/core/rng.h"
#include "src/render/render_context.h"

namespace lvox {

class EmitterPixels {
 public:
  EmitterPixels() = default;
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

  // The emission the camera sees through pixel (x, y): the mean over raysPerSample rays,
  // one jittered in each of as many strata of the pixel, of the emission of the surface
  // each meets first times transmittance(ray) (the media in front of it, ray.tmax at the
  // surface). `rays` counts the rays traced.
  template <class Transmittance>
  RGB emission(const RenderContext& ctx, int x, int y, Rng& rng, Transmittance&& transmittance,
               uint64_t& rays) const;

 private:
  int raysPerSample_ = 1;
  int rows_ = 1, cols_ = 1;  // the strata: rows_ x cols_ == raysPerSample_
  int width_ = 0;
  std::vector<char> edge_;  // per pixel: on an emitter's edge
  size_t count_ = 0;
};

template <class Transmittance>
RGB EmitterPixels::emission(const RenderContext& ctx, int x, int y, Rng& rng,
                            Transmittance&& transmittance, uint64_t& rays) const {
  const World& world = ctx.world;
  RGB sum(0.0f);
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
      if (!m.isEmissive()) continue;
      ray.tmax = hit.t;
      sum += m.emission * transmittance(ray);
    }
  return sum / static_cast<float>(rows_ * cols_);
}

}  // namespace lvox
