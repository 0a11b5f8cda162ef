#include "src/render/emitter_pixels.h"

#include <tbb/parallel_for.h>

#include <algorithm>

#include "pointcloud/gather.h"

namespace lvox {
namespace {

// The emission of the surface the camera ray through film position (px, py) meets first
// (black where it meets none).
RGB probe(const RenderContext& ctx, float px, float py) {
  SurfaceHit hit;
  if (!ctx.tracer.intersect(ctx.world.camera.generateRay(px, py), hit)) return RGB(0.0f);
  return ctx.world.materials[ctx.world.mesh.triangleMaterial[hit.triangle]].emission;
}

}  // namespace

EmitterPixels::EmitterPixels(const RenderContext& ctx, int raysPerSample)
    : raysPerSample_(std::max(1, raysPerSample)) {
  strataGrid(raysPerSample_, rows_, cols_);
  const World& world = ctx.world;
  const bool anyEmitter = std::any_of(world.materials.begin(), world.materials.end(),
                                      [](const Material& m) { return m.isEmissive(); });
  if (raysPerSample_ <= 1 || !anyEmitter) return;
  const int w = world.camera.width, h = world.camera.height;
  width_ = w;
  // Probes: the pixels' corners ((w + 1) x (h + 1)) and centres (w x h).
  const auto W = static_cast<size_t>(w);
  std::vector<RGB> corner((W + 1) * static_cast<size_t>(h + 1), RGB(0.0f));
  std::vector<RGB> centre(W * static_cast<size_t>(h), RGB(0.0f));
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
      const RGB& first = centre[static_cast<size_t>(y) * W + static_cast<size_t>(x)];
      bool shines = false, differ = false;
      auto look = [&](const RGB& e) {
        shines = shines || !isBlack(e);
        differ = differ || e != first;
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
      // An emitter, and not the same emission everywhere: an edge.
      const bool edge = shines && differ;
      edge_[static_cast<size_t>(y) * W + static_cast<size_t>(x)] = edge;
      count_ += edge;
    }
}

}  // namespace lvox
