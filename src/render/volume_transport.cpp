#include "src/render/volume_transport.h"

#include <atomic>
#include <cmath>

#include "src/core/check.h"

namespace lvox {
namespace {

using Channels = rte::Channels<float>;

// sigma_t of the heterogeneous media along a ray (homogeneous ones are done analytically).
struct HeterogeneousExtinction {
  const MediaSet& media;
  const Ray& ray;
  bool reduced = false;
  rte::MediumSample<float> eval(float t) const {
    const RGB sigmaT = media.heterogeneousSigmaT(ray.at(t), reduced);
    return {{sigmaT.x, sigmaT.y, sigmaT.z}, Channels(0.0f)};
  }
};

}  // namespace

VolumeTransport::VolumeTransport(const RenderContext& ctx, const MediaSet& media,
                                 const VolumeSettings& v)
    : ctx_(ctx),
      media_(media),
      mediumLights_(ctx.world, ctx.settings.mediumLightSamples),
      scales_(ctx.world.bounds(), media),
      lengths_{v.step, v.minStep, v.maxStep, v.stepScale} {
  if (v.solver) method_ = *v.solver;
  base_.tolerance = v.tolerance;
  base_.maxEvaluations = v.maxEvaluations;
  // T < 1e-7 from a segment's start: nothing behind is visible (rte::SolveSettings).
  base_.opaqueDepth = 16.2f;
  base_.seed = ctx.settings.seed;
  distanceSampling_ = v.sampling == rte::Sampling::kDistance;
  if (v.sampling == rte::Sampling::kEquiangular) {
    for (const Light& l : ctx.world.lights)
      if (l.type == LightType::Point || l.type == LightType::Spot) {
        equiangular_ = true;
        equiangularCentre_ = l.position;
        break;
      }
  }
  if (!v.solver) auto_.emplace(ctx.world.lights, media, scales_, lengths_, base_);
  // The scene loader refuses more media; MediaSet users index fixed arrays of this size.
  LVOX_CHECK(media.size() <= kMaxMedia, "more media than kMaxMedia");
}

rte::SolveSettings<float> VolumeTransport::segmentSettings(const Ray& ray, float t0, float t1,
                                                           float jitter) const {
  rte::SolveSettings<float> s = base_;
  s.jitter = jitter;
  lengths_.apply(scales_.step(ray, t0, t1), s);  // where the scene gives no step
  if (equiangular_) {
    // Equiangular change of variable around the point light (Kulla & Fajardo 2012).
    const Vec3 toLight = equiangularCentre_ - ray.origin;
    s.sampling = rte::Sampling::kEquiangular;
    s.delta = dot(toLight, ray.dir);
    // A ray through the light itself (h = 0) would make the map singular: 1e-4 units is
    // the documented floor (the integrand is then finite but very peaked).
    s.h = std::max(1e-4f, length(toLight - ray.dir * s.delta));
  } else if (distanceSampling_) {
    const RGB sigmaT = media_.at(ray.at(0.5f * (t0 + t1))).sigmaT();
    const float ref = maxComponent(sigmaT);
    if (ref > 0.0f) {
      s.sampling = rte::Sampling::kDistance;
      s.sigmaRef = ref;
    }
  }
  return s;
}

SegmentPlan VolumeTransport::radiancePlan(const Ray& ray, float t0, float t1, float jitter) const {
  if (auto_) return auto_->radiance(ray, t0, t1, jitter);
  return {method_, segmentSettings(ray, t0, t1, jitter)};
}

RGB VolumeTransport::transmittance(const Ray& ray, rte::SolveCounts& counts, bool reduced) const {
  if (media_.empty()) return RGB(1.0f);
  const float tmax = std::isinf(ray.tmax) ? 1e30f : ray.tmax;
  RGB tau = media_.homogeneousOpticalDepth(ray, ray.tmin, tmax, reduced);
  if (media_.anyHeterogeneous()) {
    std::vector<std::pair<float, float>> hetero;
    media_.heterogeneousIntervals(ray, ray.tmin, tmax, hetero);
    const HeterogeneousExtinction problem{media_, ray, reduced};
    for (const auto& [a, b] : hetero) {
      const SegmentPlan plan = auto_ ? auto_->transmittance(ray, a, b)
                                     : SegmentPlan{method_, segmentSettings(ray, a, b, 0.5f)};
      const rte::SolveResult<float> r =
          rte::solveTransmittance(plan.method, problem, a, b, plan.settings);
      counts += r.counts;
      tau += toRgb(r.opticalDepth);
    }
  }
  return RGB(std::exp(-tau.x), std::exp(-tau.y), std::exp(-tau.z));
}

uint64_t VolumeTransport::buildShadowCache(int resolution, uint64_t cameraRays) {
  // Over the heterogeneous media only: elsewhere shadow rays are cheap or leave them.
  Bounds3 bounds;
  for (const Medium& m : media_.media())
    if (!m.homogeneous()) bounds.extend(m.bounds);
  if (cameraRays * 16 < TransmittanceCache::nodeCount(bounds, resolution)) return 0;
  std::atomic<uint64_t> evaluations{0};
  shadowCache_ = std::make_unique<const TransmittanceCache>(
      mediumLights_.lights(), bounds, resolution, [&](const Ray& ray) {
        rte::SolveCounts counts;
        const RGB t = transmittance(ray, counts);
        evaluations += counts.mediumEvals;
        return t;
      });
  return evaluations.load();
}

uint64_t VolumeTransport::buildEnvironmentCache(int resolution, int directions,
                                                uint64_t cameraRays) {
  if (isBlack(mediumLights_.environment())) return 0;
  Bounds3 bounds;
  for (const Medium& m : media_.media())
    if (!m.homogeneous()) bounds.extend(m.bounds);
  // As for the shadow cache: it pays when the camera rays' environment samples (16 per ray
  // or more) outnumber the node's shadow rays.
  const uint64_t shadowRays =
      TransmittanceCache::nodeCount(bounds, resolution) * static_cast<uint64_t>(directions);
  if (shadowRays == 0 || cameraRays * 16 < shadowRays) return 0;
  std::atomic<uint64_t> evaluations{0};
  environmentCache_ = std::make_unique<const EnvironmentCache>(
      mediumLights_.environment(), bounds, resolution, directions,
      [&](const Ray& ray) {
        if (ctx_.tracer.occluded(ray)) return RGB(0.0f);
        rte::SolveCounts counts;
        const RGB t = transmittance(ray, counts);
        evaluations += counts.mediumEvals;
        return t;
      },
      &ctx_.tracer);
  return evaluations.load();
}

RGB VolumeTransport::singleScatterSource(const Vec3& x, const Vec3& viewDir,
                                         const MediumCoefficients* perMedium, Rng lightRng,
                                         rte::SolveCounts& counts) const {
  RGB source(0.0f);
  // `cachedLight`: the index of a point, spot or directional light whose transmittance the
  // shadow cache holds, or -1 for an exact shadow ray.
  auto add = [&](const LightSample& s, long cachedLight) {
    const Ray shadow = shadowRayFrom(x, s.wi, s.distance);
    if (ctx_.tracer.occluded(shadow)) return;
    const RGB t = cachedLight >= 0 ? shadowCache_->lookup(static_cast<size_t>(cachedLight), x)
                                   : transmittance(shadow, counts);
    const RGB arriving = s.radiance * t;
    // Light travels along -wi and leaves towards the camera along -viewDir.
    const float cosTheta = dot(s.wi, viewDir);
    for (size_t i = 0; i < media_.size(); ++i)
      if (!isBlack(perMedium[i].sigmaS))
        source += perMedium[i].sigmaS * arriving * media_[i].phase.eval(cosTheta);
  };
  // The same samples, in the same order, as LightSet::forEachSample.
  const bool useCache = shadowCache_ && shadowCache_->covers(x);
  const std::vector<Light>& lights = mediumLights_.lights();
  for (size_t l = 0; l < lights.size(); ++l) {
    const LightSample s = mediumLights_.sampleDelta(lights[l], x);
    if (isBlack(s.radiance)) continue;
    add(s, useCache && shadowCache_->cached(l) ? static_cast<long>(l) : -1);
  }
  // The constant environment from the cache, convolved with each medium's phase
  // (Funk-Hecke: band l scaled by the phase's Legendre moment chi_l); light leaving towards
  // the camera came from behind x, hence the harmonics at viewDir.
  const bool environmentCached = environmentCache_ && environmentCache_->covers(x);
  if (environmentCached) {
    RGB arriving[kShCoefficients];
    environmentCache_->lookup(x, arriving);
    float yhat[kShCoefficients];
    shBasis(viewDir, kShCoefficients, yhat);
    for (size_t i = 0; i < media_.size(); ++i) {
      if (isBlack(perMedium[i].sigmaS)) continue;
      RGB scattered[kShCoefficients];
      scattered[0] = arriving[0];
      for (int k = 1; k < kShCoefficients; ++k)
        scattered[k] = arriving[k] * media_[i].phase.moment(shBand(k));
      source += perMedium[i].sigmaS * shDot(scattered, yhat, kShCoefficients);
    }
  }
  mediumLights_.forEachAreaSample(
      x, nullptr, lightRng, [&](const LightSample& s) { add(s, -1); }, !environmentCached);
  return source;
}

namespace {

// Exact single scattering: shadow rays to every light at each medium evaluation, with the
// light samples of the camera ray fixed (a smooth integrand).
struct ExactSingleScatter {
  const VolumeTransport& transport;
  const Rng& lightRng;
  rte::SolveCounts& shadowCounts;
  RGB operator()(const Vec3& x, const Vec3& viewDir, const MediumCoefficients* perMedium) const {
    return transport.singleScatterSource(x, viewDir, perMedium, lightRng, shadowCounts);
  }
};

}  // namespace

RGB VolumeTransport::radiance(const Ray& ray, float tEnd, const RGB& background, Rng& rng,
                              rte::SolveCounts& counts, CameraRayParts* parts) const {
  if (media_.empty()) return background;
  const Rng lightRng = rng;  // the light samples of this camera ray
  rng.next();
  const float jitter = rng.uniform();
  rte::SolveCounts shadowCounts;
  const ExactSingleScatter scatter{*this, lightRng, shadowCounts};
  const RGB l = radianceWith(ray, tEnd, background, jitter, scatter, counts, parts);
  counts.mediumEvals += shadowCounts.mediumEvals;
  counts.stabilityEvents += shadowCounts.stabilityEvents;
  return l;
}

}  // namespace lvox
