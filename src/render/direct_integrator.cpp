#include "src/render/direct_integrator.h"

#include "src/render/camera_layers.h"
#include "src/render/surface_albedo.h"
#include "src/render/surface_direct.h"

namespace lvox {

void addSolveCounts(SamplerCounters& counters, const rte::SolveCounts& c) {
  if (c.mediumEvals == 0 && c.steps == 0) return;
  counters.mediumEvals.fetch_add(c.mediumEvals, std::memory_order_relaxed);
  counters.solverSteps.fetch_add(c.steps, std::memory_order_relaxed);
  counters.rejectedSteps.fetch_add(c.rejectedSteps, std::memory_order_relaxed);
  counters.stabilityEvents.fetch_add(c.stabilityEvents, std::memory_order_relaxed);
  if (c.capped) counters.cappedSegments.fetch_add(1, std::memory_order_relaxed);
}

PixelSampler directSampler(const RenderContext& ctx, const VolumeTransport& volume,
                           SamplerCounters& counters) {
  return [&ctx, &volume, &counters](const PixelSample& s, Rng& rng, SampleLayers* layers) {
    const World& world = ctx.world;
    const Ray ray = world.camera.generateRay(s.filmX, s.filmY);
    rte::SolveCounts solveCounts;
    SurfaceHit hit;
    RGB environment(0.0f), emission(0.0f), direct(0.0f);
    const bool hitSurface = ctx.tracer.intersect(ray, hit);
    if (hitSurface) {
      const Material& m = world.materials[world.mesh.triangleMaterial[hit.triangle]];
      uint64_t shadowRays = 0;
      auto throughMedia = [&](const Ray& shadow) {
        return volume.transmittance(shadow, solveCounts);
      };
      const RGB albedo = cameraHitAlbedo(ctx, m, ray, hit);
      emission = m.emission;
      direct = surfaceDirect(ctx, hit, albedo, rng, throughMedia, shadowRays);
      counters.shadowRays.fetch_add(shadowRays, std::memory_order_relaxed);
      if (layers) fillSurfaceLayers(*layers, hit, albedo);
    } else {
      environment = ctx.lights.environment(ray.dir);
    }
    CameraRayParts parts;
    const RGB l = volume.radiance(ray, hitSurface ? hit.t : kInf, emission + direct + environment,
                                  rng, solveCounts, layers ? &parts : nullptr);
    if (layers) fillRadianceLayers(*layers, parts, emission, direct, RGB(0.0f), environment);
    addSolveCounts(counters, solveCounts);
    return l;
  };
}

}  // namespace lvox
