#pragma once
// Light transport through the scene's media in direct mode: transmittance of shadow rays
// and, along camera rays, the RTE with emission and single scattering solved by the
// selected method (volume/rte). Only the intervals where a medium may be non-zero are
// integrated (empty space is skipped by the media's own structure).
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "src/render/auto_solver.h"
#include "src/render/environment_cache.h"
#include "src/render/render_context.h"
#include "src/render/transmittance_cache.h"
#include "volume/media/media_set.h"
#include "volume/rte/solve.h"
#include "volume/volume_settings.h"

namespace lvox {

// What a camera ray's media add, for the AOV layers (layers.h): the radiance is
// inScatter + emission + transmittance x background. `emission` is the media's own
// emission along the ray, solved again without the scatter source (only when a medium
// emits); `inScatter` is the rest of the media's radiance, so the parts add up exactly.
struct CameraRayParts {
  RGB inScatter{0.0f}, emission{0.0f}, transmittance{1.0f};
};

// The in-scatter source of a solve that wants the media's emission alone.
struct NoScatter {
  RGB operator()(const Vec3&, const Vec3&, const MediumCoefficients*) const { return RGB(0.0f); }
};

class VolumeTransport {
 public:
  VolumeTransport(const RenderContext& ctx, const MediaSet& media, const VolumeSettings& settings);

  bool empty() const { return media_.empty(); }
  const MediaSet& media() const { return media_; }

  // Fraction of light surviving along [ray.tmin, ray.tmax]: analytic through homogeneous
  // media, the selected solver (T' = -sigma_t T) through heterogeneous ones. `reduced`:
  // through the media without their phases' forward peaks (MediaSet::heterogeneousSigmaT),
  // the light pcb's anisotropic lvoxels treat as not scattered.
  RGB transmittance(const Ray& ray, rte::SolveCounts& counts, bool reduced = false) const;

  // Radiance reaching ray.origin along [0, tEnd] when `background` arrives from tEnd,
  // with emission and exact single scattering (shadow rays at every medium evaluation).
  // With `parts`, also what each part contributes (CameraRayParts).
  RGB radiance(const Ray& ray, float tEnd, const RGB& background, Rng& rng,
               rte::SolveCounts& counts, CameraRayParts* parts = nullptr) const;

  // The same with another in-scatter source: `scatter(x, viewDir, perMedium)` returns
  // the scattered radiance source sum_m sigma_s,m * (phase-weighted incident light) at x.
  template <class ScatterSource>
  RGB radianceWith(const Ray& ray, float tEnd, const RGB& background, float jitter,
                   const ScatterSource& scatter, rte::SolveCounts& counts,
                   CameraRayParts* parts = nullptr) const;

  // In-scattered radiance from the lights at x towards -viewDir, per unit sigma_s of each
  // medium: sum_m sigma_s,m * sum_l p_m(cos) L_l V T. `lightRng` fixes the light samples.
  RGB singleScatterSource(const Vec3& x, const Vec3& viewDir, const MediumCoefficients* perMedium,
                          Rng lightRng, rte::SolveCounts& counts) const;

  // Solves the transmittance to every point, spot and directional light once per node of a
  // grid of `resolution` cells over the heterogeneous media (volume_integrator.shadow_cache);
  // from then on singleScatterSource looks it up inside them. Built only when it pays: when
  // `cameraRays` x 16 (fewer in-scatter samples than any ray through a medium takes)
  // reaches the grid's nodes. Returns the evaluations spent (0: not built).
  uint64_t buildShadowCache(int resolution, uint64_t cameraRays);
  const TransmittanceCache* shadowCache() const { return shadowCache_.get(); }
  // The constant environment's light in the heterogeneous media, cached at `resolution`
  // cells along their longest side from `directions` shadow rays per node
  // (volume_integrator.environment_cache); from then on singleScatterSource takes the
  // environment from it inside them. Built when the scene has a constant environment and
  // `cameraRays` x 16 reaches the shadow rays it solves. Returns the evaluations spent.
  uint64_t buildEnvironmentCache(int resolution, int directions, uint64_t cameraRays);
  const EnvironmentCache* environmentCache() const { return environmentCache_.get(); }

 private:
  rte::SolveSettings<float> segmentSettings(const Ray& ray, float t0, float t1, float jitter) const;
  // The method and settings of one camera-ray segment: the scene's, or auto's choice.
  SegmentPlan radiancePlan(const Ray& ray, float t0, float t1, float jitter) const;

  static rte::Channels<float> toChannels(const RGB& c) { return {c.x, c.y, c.z}; }
  static RGB toRgb(const rte::Channels<float>& c) { return {c[0], c[1], c[2]}; }

  const RenderContext& ctx_;
  const MediaSet& media_;
  LightSet mediumLights_;  // render.medium_light_samples per area light and environment
  rte::Method method_ = rte::Method::kRk4;
  MediumScales scales_;
  StepLengths lengths_;
  std::optional<AutoSolver> auto_;  // the solver "auto"
  std::unique_ptr<const TransmittanceCache> shadowCache_;
  std::unique_ptr<const EnvironmentCache> environmentCache_;
  rte::SolveSettings<float> base_;
  bool equiangular_ = false;
  bool distanceSampling_ = false;
  Vec3 equiangularCentre_;
};

// The RTE along a camera ray: sigma_t of all media, emission plus the in-scatter source.
template <class ScatterSource>
struct CameraRayProblem {
  const MediaSet& media;
  const Ray& ray;
  const ScatterSource& scatter;
  rte::MediumSample<float> eval(float t) const {
    const Vec3 x = ray.at(t);
    MediumCoefficients perMedium[kMaxMedia];
    RGB sigmaT(0.0f), source(0.0f);
    bool scatters = false;
    for (size_t i = 0; i < media.size(); ++i) {
      if (!media[i].bounds.contains(x)) continue;
      perMedium[i] = media[i].at(x);
      sigmaT += perMedium[i].sigmaT();
      source += perMedium[i].source;
      scatters = scatters || !isBlack(perMedium[i].sigmaS);
    }
    if (scatters) source += scatter(x, ray.dir, perMedium);
    return {{sigmaT.x, sigmaT.y, sigmaT.z}, {source.x, source.y, source.z}};
  }
};

template <class ScatterSource>
RGB VolumeTransport::radianceWith(const Ray& ray, float tEnd, const RGB& background, float jitter,
                                  const ScatterSource& scatter, rte::SolveCounts& counts,
                                  CameraRayParts* parts) const {
  if (media_.empty()) return background;
  thread_local std::vector<std::pair<float, float>> spans;
  spans.clear();
  media_.intervals(ray, 0.0f, std::isinf(tEnd) ? 1e30f : tEnd, spans);
  if (spans.empty()) return background;
  RGB radiance(0.0f), throughput(1.0f), emission(0.0f);
  const CameraRayProblem<ScatterSource> problem{media_, ray, scatter};
  const bool splitEmission = parts && media_.anyEmissive();
  const NoScatter noScatter;
  const CameraRayProblem<NoScatter> emissionProblem{media_, ray, noScatter};
  for (const auto& [a, b] : spans) {
    const SegmentPlan plan = radiancePlan(ray, a, b, jitter);
    const float end = std::min(b, plan.end);
    const rte::SolveResult<float> r =
        rte::solve(plan.method, problem, a, end, rte::Channels<float>(0.0f), plan.settings);
    counts += r.counts;
    if (splitEmission) {
      const rte::SolveResult<float> e = rte::solve(plan.method, emissionProblem, a, end,
                                                   rte::Channels<float>(0.0f), plan.settings);
      counts += e.counts;
      emission += throughput * toRgb(e.radiance);
    }
    radiance += throughput * toRgb(r.radiance);
    throughput *= toRgb(r.transmittance);
    if (maxComponent(throughput) < 1e-6f) break;
  }
  if (parts) {
    // Emission alone cannot exceed the whole (the solves differ by their tolerance only).
    for (int c = 0; c < 3; ++c) emission[c] = std::clamp(emission[c], 0.0f, radiance[c]);
    parts->emission = emission;
    parts->inScatter = radiance - emission;
    parts->transmittance = throughput;
  }
  return radiance + throughput * background;
}

}  // namespace lvox
