#include "src/render/mc_integrator.h"

#include <algorithm>
#include <cmath>

#include "src/core/sampling.h"
#include "src/render/surface_albedo.h"

namespace lvox {
namespace {

struct PathCounters {
  uint64_t rays = 0;
  uint64_t paths = 0;
  uint64_t lookups = 0;
};

float powerHeuristic(float a, float b) { return a * a / (a * a + b * b); }

// Transmittance of a shadow ray that no surface blocks.
RGB shadowTransmittance(const MajorantTracker& tracker, const Ray& shadow, Rng& rng,
                        PathCounters& counters) {
  return tracker.transmittance(shadow, rng, counters.lookups);
}

// Next-event estimation at a surface vertex. Area-light samples are weighted against
// cosine-sampled continuation rays that hit the same emitter (power heuristic): alone,
// either has unbounded variance somewhere (NEE next to an emitter, 1/d^2; continuation
// towards small emitters). Delta lights and a constant environment come from NEE only; an
// environment map's samples are weighted against continuation rays that escape, as emitters.
RGB surfaceNee(const RenderContext& ctx, const MajorantTracker& tracker, const SurfaceHit& hit,
               const RGB& albedo, Rng& rng, PathCounters& counters) {
  RGB sum(0.0f);
  ctx.lights.forEachSample(hit.point, &hit.normal, rng, [&](const LightSample& s) {
    if (dot(s.wi, hit.normal) <= 0.0f) return;  // below the geometric surface
    const float cosTheta = dot(s.wi, hit.shading);
    if (cosTheta <= 0.0f) return;
    ++counters.rays;
    const Ray shadow = ctx.spawn(hit.point, hit.normal, s.wi, s.distance);
    if (ctx.tracer.occluded(shadow)) return;
    const float weight =
        s.fromEmitter || s.fromEnvironment ? powerHeuristic(s.pdf, cosTheta * kInvPi) : 1.0f;
    sum += s.radiance * shadowTransmittance(tracker, shadow, rng, counters) * (cosTheta * weight);
  });
  return albedo * sum * kInvPi;
}

// Next-event estimation at a medium scattering point (phase function instead of BRDF;
// the phase's own sampling is not MIS-weighted, so continuation rays add no emission).
// Point and spot lights are left out: their in-scattering along the whole segment is
// estimated by equiangularInScatter, which has finite variance where this would not.
RGB mediumNee(const RenderContext& ctx, const MajorantTracker& tracker, const Vec3& x,
              const Vec3& dir, const PhaseFunction& phase, Rng& rng, PathCounters& counters) {
  RGB sum(0.0f);
  auto add = [&](const LightSample& s) {
    ++counters.rays;
    const Ray shadow = shadowRayFrom(x, s.wi, s.distance);
    if (ctx.tracer.occluded(shadow)) return;
    // Light travels along -wi and continues along -dir towards the previous vertex.
    sum += s.radiance * shadowTransmittance(tracker, shadow, rng, counters) *
           phase.eval(dot(s.wi, dir));
  };
  for (const Light& light : ctx.lights.lights())
    if (light.type == LightType::Directional) add(ctx.lights.sampleDelta(light, x));
  ctx.lights.forEachAreaSample(x, nullptr, rng, add);
  return sum;
}

// Light of point and spot lights scattered once on the segment [0, tEnd] of a path, one
// equiangular sample per light (Kulla & Fajardo 2012): pdf proportional to 1/r^2 of the
// light, so the estimate is bounded even for rays through the light. With delta tracking,
// NEE at a collision would carry 1/r^2, whose second moment diverges near the light.
// Transmittance to the sample and to the light by ratio tracking; unbiased.
RGB equiangularInScatter(const RenderContext& ctx, const MajorantTracker& tracker, const Ray& ray,
                         float tEnd, Rng& rng, PathCounters& counters) {
  const MediaSet& media = tracker.media();
  const std::vector<Light>& lights = ctx.lights.lights();
  if (std::none_of(lights.begin(), lights.end(),
                   [](const Light& l) { return l.type != LightType::Directional; }))
    return RGB(0.0f);  // no point or spot light: no walk for the media's extent
  thread_local std::vector<std::pair<float, float>> spans;
  spans.clear();
  media.intervals(ray, 0.0f, std::isinf(tEnd) ? 1e30f : tEnd, spans);
  if (spans.empty()) return RGB(0.0f);
  const float a = spans.front().first, b = spans.back().second;
  RGB sum(0.0f);
  for (const Light& light : lights) {
    if (light.type == LightType::Directional) continue;
    const Vec3 toLight = light.position - ray.origin;
    const float delta = dot(toLight, ray.dir);
    const float h = std::max(1e-4f, length(toLight - ray.dir * delta));
    const EquiangularSampler equiangular(delta, h, a, b);
    if (!equiangular.valid()) continue;
    const float t = equiangular.sample(rng.uniform());
    const float pdf = equiangular.pdf(t);
    const Vec3 x = ray.at(t);
    const LightSample s = ctx.lights.sampleDelta(light, x);
    if (isBlack(s.radiance) || !(pdf > 0.0f)) continue;
    RGB scatter(0.0f);
    for (const Medium& m : media.media()) {
      if (!m.bounds.contains(x)) continue;
      ++counters.lookups;
      scatter += m.at(x).sigmaS * m.phase.eval(dot(s.wi, ray.dir));
    }
    if (isBlack(scatter)) continue;
    Ray shadow{x, s.wi, 0.0f, s.distance * (1.0f - 1e-4f)};
    ++counters.rays;
    if (ctx.tracer.occluded(shadow)) continue;
    const Ray toSample{ray.origin, ray.dir, 0.0f, t};
    const RGB tr = shadowTransmittance(tracker, toSample, rng, counters) *
                   shadowTransmittance(tracker, shadow, rng, counters);
    sum += scatter * s.radiance * tr / pdf;
  }
  return sum;
}

struct Collision {
  bool scattered = false;
  bool absorbed = false;
  float t = 0.0f;
  size_t medium = 0;  // the medium whose phase function scatters
};

// The medium whose phase function scatters at x, picked in proportion to its sigma_s.
size_t scatteringMedium(const MediaSet& media, const Vec3& x, float totalSigmaS, Rng& rng) {
  if (media.size() <= 1) return 0;
  size_t picked = 0;
  float pick = rng.uniform() * totalSigmaS;
  for (size_t i = 0; i < media.size(); ++i) {
    if (!media[i].bounds.contains(x)) continue;
    pick -= average(media[i].at(x).sigmaS);
    picked = i;
    if (pick <= 0.0f) break;
  }
  return picked;
}

// Weighted delta tracking along [0, tEnd]: updates the throughput for null and scattering
// events (per channel, against channel-averaged event probabilities) and adds emission on
// absorption. Returns where the path scatters or is absorbed, if it does.
Collision deltaTrack(const MajorantTracker& tracker, const Ray& ray, float tEnd, Rng& rng,
                     RGB& throughput, RGB& radiance, PathCounters& counters) {
  Collision c;
  thread_local std::vector<MajorantSpan> segs;
  tracker.segments(ray, 0.0f, std::isinf(tEnd) ? 1e30f : tEnd, false, segs);
  const MediaSet& media = tracker.media();
  forEachTentativeCollision(segs, rng, [&](float t, float majorant) {
    const Vec3 x = ray.at(t);
    const MediumCoefficients total = media.at(x);
    ++counters.lookups;
    const float pA = average(total.sigmaA) / majorant;
    const float pS = average(total.sigmaS) / majorant;
    const float u = rng.uniform();
    if (u < pA) {
      radiance += throughput * total.source / (majorant * pA);
      c.absorbed = true;
      c.t = t;
      return false;
    }
    if (u < pA + pS) {
      throughput *= total.sigmaS / (majorant * pS);
      c.scattered = true;
      c.t = t;
      c.medium = scatteringMedium(media, x, average(total.sigmaS), rng);
      return false;
    }
    const float pN = 1.0f - pA - pS;
    const RGB sigmaN = RGB(majorant) - total.sigmaA - total.sigmaS;
    throughput *=
        RGB(std::max(0.0f, sigmaN.x), std::max(0.0f, sigmaN.y), std::max(0.0f, sigmaN.z)) /
        (majorant * std::max(pN, 1e-12f));
    return true;
  });
  return c;
}

// A path's radiance split by its first vertex (layers.h): what the first surface reflects
// of the lights' direct light, what it reflects after more scattering, what the media on
// the camera ray scatter towards it, what is seen emitting, and the environment seen.
struct PathParts {
  RGB direct{0.0f}, indirect{0.0f}, volume{0.0f}, emission{0.0f}, environment{0.0f};
  RGB sum() const { return direct + indirect + volume + emission + environment; }
};

// Emitters hit by continuation rays count with the MIS weight that complements
// surfaceNee; escaping continuation rays add an environment map's radiance the same way
// (a constant environment is NEE only).
void tracePath(const RenderContext& ctx, const MajorantTracker& tracker, Ray ray, Rng& rng,
               PathCounters& counters, PathParts& parts, SampleLayers* layers) {
  const World& world = ctx.world;
  const int maxEvents = ctx.settings.maxBounces;
  RGB throughput(1.0f);
  // Where light goes once the first vertex is known: indirect after a surface, volume
  // after a scattering in a medium.
  RGB* later = nullptr;
  float bsdfPdf = 0.0f;  // solid-angle pdf of the surface continuation being traced (0: none)
  const bool media = !tracker.media().empty();
  ++counters.paths;
  for (int event = 1;; ++event) {
    const bool first = event == 1;
    SurfaceHit hit;
    ++counters.rays;
    const bool hitSurface = ctx.tracer.intersect(ray, hit);
    if (media) {
      if (event <= maxEvents)
        (first ? parts.volume : *later) +=
            throughput *
            equiangularInScatter(ctx, tracker, ray, hitSurface ? hit.t : kInf, rng, counters);
      const Collision c = deltaTrack(tracker, ray, hitSurface ? hit.t : kInf, rng, throughput,
                                     first ? parts.emission : *later, counters);
      if (c.absorbed) break;
      if (c.scattered) {
        if (event > maxEvents) break;
        if (first) later = &parts.volume;
        const Vec3 x = ray.at(c.t);
        const PhaseFunction& phase = tracker.media()[c.medium].phase;
        *later += throughput * mediumNee(ctx, tracker, x, ray.dir, phase, rng, counters);
        if (event >= 3) {
          const float survive = std::min(1.0f, maxComponent(throughput));
          if (rng.uniform() >= survive) break;
          throughput /= survive;
        }
        float pdf;
        const Vec3 next = phase.sample(ray.dir, rng.uniform(), rng.uniform(), pdf);
        ray = Ray{x, next, 0.0f, kInf};
        bsdfPdf = 0.0f;  // phase sampling is not MIS-weighted against emitters
        continue;
      }
    }
    if (!hitSurface) {
      const EnvironmentMap* map = ctx.lights.environmentMap();
      if (first)
        parts.environment += throughput * ctx.lights.environment(ray.dir);
      else if (map && bsdfPdf > 0.0f)  // the MIS complement of the map's NEE samples
        *later += throughput * map->radiance(ray.dir) * powerHeuristic(bsdfPdf, map->pdf(ray.dir));
      break;
    }
    const Material& m = world.materials[world.mesh.triangleMaterial[hit.triangle]];
    if (first) {
      parts.emission += throughput * m.emission;
      later = &parts.indirect;
    } else if (m.isEmissive() && bsdfPdf > 0.0f) {
      const float lightPdf = ctx.lights.emitterPdf(ray.origin, hit.triangle, hit.t,
                                                   std::abs(dot(hit.normal, ray.dir)));
      *later += throughput * m.emission * powerHeuristic(bsdfPdf, lightPdf);
    }
    if (first && layers) {
      layers->hit = true;
      layers->depth = hit.t;
      layers->normal = hit.shading;
      layers->albedo = cameraHitAlbedo(ctx, m, ray, hit);
    }
    if (event > maxEvents) break;
    const RGB albedo = first ? cameraHitAlbedo(ctx, m, ray, hit) : hitAlbedo(ctx, m, hit);
    (first ? parts.direct : *later) +=
        throughput * surfaceNee(ctx, tracker, hit, albedo, rng, counters);
    // After the last allowed event the continuation ray is still traced: it can only add
    // emission (the MIS complement of this vertex's NEE), never another scattering.
    // Cosine-weighted continuation: f cos / pdf = albedo.
    throughput *= albedo;
    if (event >= 3) {
      const float survive = std::min(1.0f, maxComponent(throughput));
      if (rng.uniform() >= survive) break;
      throughput /= survive;
    }
    if (isBlack(throughput)) break;
    const Vec3 local = cosineHemisphere(rng.uniform(), rng.uniform());
    bsdfPdf = cosineHemispherePdf(local.z);
    // Sampled about the shading normal; a direction below the geometric surface ends the
    // path (smooth normals must not let light through the geometry).
    const Vec3 next = Frame(hit.shading).toWorld(local);
    if (dot(next, hit.normal) <= 0.0f) break;
    ray = ctx.spawn(hit.point, hit.normal, next);
  }
}

}  // namespace

PixelSampler monteCarloSampler(const RenderContext& neeCtx, const MajorantTracker& tracker,
                               SamplerCounters& counters) {
  return [&neeCtx, &tracker, &counters](const PixelSample& s, Rng& rng, SampleLayers* layers) {
    PathCounters local;
    const Ray ray = neeCtx.world.camera.generateRay(s.filmX, s.filmY);
    PathParts parts;
    tracePath(neeCtx, tracker, ray, rng, local, parts, layers);
    if (layers) {
      layers->direct = parts.direct;
      layers->indirect = parts.indirect;
      layers->volume = parts.volume;
      layers->emission = parts.emission;
      layers->environment = parts.environment;
    }
    const RGB l = parts.sum();
    counters.pathRays.fetch_add(local.rays, std::memory_order_relaxed);
    counters.paths.fetch_add(local.paths, std::memory_order_relaxed);
    counters.mediumEvals.fetch_add(local.lookups, std::memory_order_relaxed);
    return l;
  };
}

}  // namespace lvox
