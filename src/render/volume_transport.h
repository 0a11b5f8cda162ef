#pragma once
// Light transport through the scene's media in direct mode: transmittance of shadow rays
// and, along camera rays, the RTE with emission and single scattering solved by the
// selected method (volume/rte). Only the intervals where a medium may be non-zero are
// integrated (empty space is skipped by the media's own structure).
#include <vector>

#include "src/render/render_context.h"
#include "volume/media/media_set.h"
#include "volume/rte/solve.h"

namespace lvox {

class VolumeTransport {
 public:
  VolumeTransport(const RenderContext& ctx, const MediaSet& media);

  bool empty() const { return media_.empty(); }
  const MediaSet& media() const { return media_; }
  rte::Method method() const { return method_; }

  // Fraction of light surviving along [ray.tmin, ray.tmax]: analytic through homogeneous
  // media, the selected solver (T' = -sigma_t T) through heterogeneous ones.
  RGB transmittance(const Ray& ray, rte::SolveCounts& counts) const;

  // Radiance reaching ray.origin along [0, tEnd] when `background` arrives from tEnd.
  RGB radiance(const Ray& ray, float tEnd, const RGB& background, Rng& rng,
               rte::SolveCounts& counts) const;

  // In-scattered radiance from the lights at x towards -viewDir, per unit sigma_s of each
  // medium: sum_m sigma_s,m * sum_l p_m(cos) L_l V T. `lightRng` fixes the light samples.
  RGB singleScatterSource(const Vec3& x, const Vec3& viewDir, const MediumCoefficients* perMedium,
                          Rng lightRng, rte::SolveCounts& counts) const;

 private:
  rte::SolveSettings<float> segmentSettings(const Ray& ray, float t0, float t1, float jitter) const;

  const RenderContext& ctx_;
  const MediaSet& media_;
  LightSet mediumLights_;  // render.medium_light_samples per area light and environment
  rte::Method method_;
  rte::SolveSettings<float> base_;
  bool equiangular_ = false;
  bool distanceSampling_ = false;
  Vec3 equiangularCentre_;
};

}  // namespace lvox
