#include "src/render/mc_integrator.h"

#include "src/render/tile_renderer.h"

namespace lvox {
namespace {

struct PathCounters {
  uint64_t rays = 0;
  uint64_t paths = 0;
};

float powerHeuristic(float a, float b) { return a * a / (a * a + b * b); }

// Next-event estimation at a surface vertex. Area-light samples are weighted against
// cosine-sampled continuation rays that hit the same emitter (power heuristic): alone,
// either has unbounded variance somewhere (NEE next to an emitter, 1/d^2; continuation
// towards small emitters). Delta lights and the environment come from NEE only.
RGB surfaceNee(const RenderContext& ctx, const SurfaceHit& hit, const RGB& albedo, Rng& rng,
               uint64_t& rays) {
  RGB sum(0.0f);
  ctx.lights.forEachSample(hit.point, &hit.normal, rng, [&](const LightSample& s) {
    const float cosTheta = dot(s.wi, hit.normal);
    if (cosTheta <= 0.0f) return;
    ++rays;
    if (ctx.tracer.occluded(ctx.spawn(hit.point, hit.normal, s.wi, s.distance))) return;
    const float weight = s.fromEmitter ? powerHeuristic(s.pdf, cosTheta * kInvPi) : 1.0f;
    sum += s.radiance * (cosTheta * weight);
  });
  return albedo * sum * kInvPi;
}

// Emitters hit by continuation rays count with the MIS weight that complements
// surfaceNee; escaping continuation rays add nothing (the environment is NEE only).
RGB tracePath(const RenderContext& ctx, const LightSet& neeLights, Ray ray, Rng& rng,
              PathCounters& counters) {
  const Scene& scene = ctx.scene;
  const int maxEvents = scene.render.maxBounces;
  RGB radiance(0.0f), throughput(1.0f);
  const RenderContext neeCtx{scene, ctx.tracer, neeLights};
  float bsdfPdf = 0.0f;  // solid-angle pdf of the continuation ray that is being traced
  ++counters.paths;
  for (int event = 1;; ++event) {
    SurfaceHit hit;
    ++counters.rays;
    if (!ctx.tracer.intersect(ray, hit)) {
      if (event == 1) radiance += throughput * ctx.lights.environment();
      break;
    }
    const Material& m = scene.materials[scene.mesh.triangleMaterial[hit.triangle]];
    if (event == 1) {
      radiance += throughput * m.emission;
    } else if (m.isEmissive()) {
      const float lightPdf = neeLights.areaPdf(hit.t, std::abs(dot(hit.normal, ray.dir)));
      radiance += throughput * m.emission * powerHeuristic(bsdfPdf, lightPdf);
    }
    if (event > maxEvents) break;
    radiance += throughput * surfaceNee(neeCtx, hit, m.albedo, rng, counters.rays);
    // After the last allowed event the continuation ray is still traced: it can only add
    // emission (the MIS complement of this vertex's NEE), never another scattering.
    // Cosine-weighted continuation: f cos / pdf = albedo.
    throughput *= m.albedo;
    if (event >= 3) {
      const float survive = std::min(1.0f, maxComponent(throughput));
      if (rng.uniform() >= survive) break;
      throughput /= survive;
    }
    if (isBlack(throughput)) break;
    const Vec3 local = cosineHemisphere(rng.uniform(), rng.uniform());
    bsdfPdf = cosineHemispherePdf(local.z);
    ray = ctx.spawn(hit.point, hit.normal, Frame(hit.normal).toWorld(local));
  }
  return radiance;
}

}  // namespace

PixelSampler monteCarloSampler(const RenderContext& ctx, const LightSet& neeLights,
                               SamplerCounters& counters) {
  return [&ctx, &neeLights, &counters](int x, int y, Rng& rng) {
    PathCounters local;
    const Ray ray = ctx.scene.camera.generateRay(static_cast<float>(x) + rng.uniform(),
                                                 static_cast<float>(y) + rng.uniform());
    const RGB l = tracePath(ctx, neeLights, ray, rng, local);
    counters.pathRays.fetch_add(local.rays, std::memory_order_relaxed);
    counters.paths.fetch_add(local.paths, std::memory_order_relaxed);
    return l;
  };
}

}  // namespace lvox
