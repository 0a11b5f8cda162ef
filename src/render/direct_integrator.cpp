#include "src/render/direct_integrator.h"

#include <atomic>

#include "src/render/surface_direct.h"
#include "src/render/tile_renderer.h"

namespace lvox {

Image renderDirect(const RenderContext& ctx, Report& report) {
  const Scene& scene = ctx.scene;
  const Camera& cam = scene.camera;
  std::atomic<uint64_t> shadowRaysTotal{0};
  auto noMedia = [](const Ray&) { return RGB(1.0f); };
  PixelSampler sample = [&](int x, int y, Rng& rng) {
    const Ray ray = cam.generateRay(static_cast<float>(x) + rng.uniform(),
                                    static_cast<float>(y) + rng.uniform());
    SurfaceHit hit;
    if (!ctx.tracer.intersect(ray, hit)) return ctx.lights.environment();
    const Material& m = scene.materials[scene.mesh.triangleMaterial[hit.triangle]];
    uint64_t shadowRays = 0;
    const RGB reflected = surfaceDirect(ctx, hit, m.albedo, rng, noMedia, shadowRays);
    shadowRaysTotal.fetch_add(shadowRays, std::memory_order_relaxed);
    return m.emission + reflected;
  };
  TileStats stats;
  Image image;
  {
    PhaseTimer timer(report, "render");
    image = renderTiles(cam.width, cam.height, scene.render.spp, scene.render.seed, sample, stats);
  }
  report.add("camera_rays", stats.samples);
  report.add("shadow_rays", shadowRaysTotal.load());
  report.add("invalid_samples", stats.invalidSamples);
  return image;
}

}  // namespace lvox
