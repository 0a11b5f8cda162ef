#include "src/render/emitter_pixels.h"

#include <tbb/parallel_for.h>

#include <algorithm>

#include "pointcloud/gather.h"

namespace lvox {
namespace {

// Which emitter the camera ray through film position (px, py) meets first: its material,
// or -1 where it meets a surface that emits nothing, or none. Two emitters of one emission
// but different materials then count as different, which only adds rays along where they
// touch; a material index takes a third of an RGB's memory (the probes of an image of
// 3840 x 2160 pixels take 66 MB).
int32_t probe(const RenderContext& ctx, float px, float py) {
  SurfaceHit hit;
  if (!ctx.tracer.intersect(ctx.world.camera.generateRay(px, py), hit)) return -1;
  const uint32_t material = ctx.world.mesh.triangleMaterial[hit.triangle];
  return ctx.world.materials[material].isEmissive() ? static_cast<int32_t>(material) : -1;
}

}  // namespace

EmitterPixels::EmitterPixels(const RenderContext& ctx, int raysPerSample)
    : raysPerSample_(std::max(1, raysPerSample)),
      lightSamples_(edgeLightSamples(ctx.settings.areaLightSamples)),
      lights_(std::make_unique<const LightSet>(ctx.world, lightSamples_)) {
  strataGrid(raysPerSample_, rows_, cols_);
  const World& world = ctx.world;
  const bool anyEmitter = std::any_of(world.materials.begin(), world.materials.end(),
                                      [](const Material& m) { return m.isEmissive(); });
  if (raysPerSample_ <= 1 || !anyEmitter) return;
  const int w = world.camera.width, h = world.camera.height;
  width_ = w;
  // Probes: the pixels' corners ((w + 1) x (h + 1)) and centres (w x h).
  const auto W = static_cast<size_t>(w);
  std::vector<int32_t> corner((W + 1) * static_cast<size_t>(h + 1), -1);
  std::vector<int32_t> centre(W * static_cast<size_t>(h), -1);
  tbb::parallel_for(0, h + 1, [&](int y) {
    const auto row = static_cast<size_t>(y);
    for (int x = 0; x <= w; ++x) {
      const auto column = static_cast<size_t>(x);
      corner[row * (W + 1) + column] = probe(ctx, static_cast<float>(x), static_cast<float>(y));
      if (x < w && y < h)
        centre[row * W + column] =
            probe(ctx, static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
    }
  });
  edge_.assign(centre.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // The probes: the pixel's corners and centre, its neighbours' centres.
      const int32_t first = centre[static_cast<size_t>(y) * W + static_cast<size_t>(x)];
      bool shines = false, differ = false;
      auto look = [&](int32_t emitter) {
        shines = shines || emitter >= 0;
        differ = differ || emitter != first;
      };
      for (int dy = 0; dy <= 1; ++dy)
        for (int dx = 0; dx <= 1; ++dx)
          look(corner[static_cast<size_t>(y + dy) * (W + 1) + static_cast<size_t>(x + dx)]);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx >= 0 && nx < w && ny >= 0 && ny < h)
            look(centre[static_cast<size_t>(ny) * W + static_cast<size_t>(nx)]);
        }
      // An emitter, and not the same one everywhere: an edge.
      const bool edge = shines && differ;
      edge_[static_cast<size_t>(y) * W + static_cast<size_t>(x)] = edge;
      count_ += edge;
    }
}

}  // namespace lvox
