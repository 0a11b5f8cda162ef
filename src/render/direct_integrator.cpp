#include "src/render/direct_integrator.h"

#include "src/render/surface_direct.h"

namespace lvox {

PixelSampler directSampler(const RenderContext& ctx, SamplerCounters& counters) {
  return [&ctx, &counters](int x, int y, Rng& rng) {
    const Scene& scene = ctx.scene;
    const Ray ray = scene.camera.generateRay(static_cast<float>(x) + rng.uniform(),
                                             static_cast<float>(y) + rng.uniform());
    SurfaceHit hit;
    if (!ctx.tracer.intersect(ray, hit)) return ctx.lights.environment();
    const Material& m = scene.materials[scene.mesh.triangleMaterial[hit.triangle]];
    uint64_t shadowRays = 0;
    auto noMedia = [](const Ray&) { return RGB(1.0f); };
    const RGB reflected = surfaceDirect(ctx, hit, m.albedo, rng, noMedia, shadowRays);
    counters.shadowRays.fetch_add(shadowRays, std::memory_order_relaxed);
    return m.emission + reflected;
  };
}

}  // namespace lvox
