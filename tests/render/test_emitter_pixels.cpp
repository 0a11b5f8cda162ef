// Emitters seen directly: which pixels get rays of their own, and what those rays estimate.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include "src/render/emitter_pixels.h"
#include "src/render/renderer.h"
#include "src/render/surface_direct.h"
#include "src/scene/scene_loader.h"

namespace lvox {
namespace {

// A square of radiance 2, turned by 30 degrees about the view axis so that no edge runs
// along the pixels, seen head-on, 32 x 32 pixels: an emitter against nothing, or a grey
// card against an environment of radiance 1.
Scene squareScene(bool lamp, const std::string& render = R"("render": {},)") {
  const std::string square =
      R"("shapes": [{"type": "quad", "corners": [[-0.2, -0.85, 0], [0.85, -0.2, 0], [0.2, 0.85, 0], [-0.85, 0.2, 0]], "material": "m"}])";
  return parseScene(
      std::string(R"({
    "camera": {"position": [0, 0, -3], "look_at": [0, 0, 0], "vfov_deg": 40, "width": 32, "height": 32},)") +
          render +
          (lamp
               ? R"("materials": {"m": {"albedo": 0, "emission": 2}},)"
               : R"("materials": {"m": {"albedo": 0.5}}, "lights": [{"type": "environment", "radiance": 1}],)") +
          square + "}",
      "/tmp/emitter-pixels.json");
}

// The square's scene with what the camera needs to trace it.
struct SquareView {
  Scene scene;
  RayTracer tracer{scene.world.mesh};
  LightSet lights{scene.world, 1};
  RenderContext ctx{scene.world, scene.render, tracer, lights};
  explicit SquareView(bool lamp) : scene(squareScene(lamp)) {}
};

// The emission part of what an EmitterPixels sees through pixel (x, y).
RGB emissionOf(const EmitterPixels& pixels, const RenderContext& ctx, int x, int y, Rng& rng,
               const std::function<RGB(const Ray&)>& transmittance, uint64_t& rays) {
  uint64_t shadowRays = 0;
  auto clear = [](const Ray&) { return RGB(1.0f); };
  return pixels.seen(ctx, x, y, rng, transmittance, clear, LightSubset{}, rays, shadowRays)
      .emission;
}

// The share of pixel (x, y) the emitter covers, by a regular 32 x 32 grid of rays.
double coverage(const RenderContext& ctx, int x, int y) {
  int inside = 0;
  for (int j = 0; j < 32; ++j)
    for (int i = 0; i < 32; ++i) {
      SurfaceHit hit;
      const float px = static_cast<float>(x) + (static_cast<float>(i) + 0.5f) / 32.0f;
      const float py = static_cast<float>(y) + (static_cast<float>(j) + 0.5f) / 32.0f;
      inside += ctx.tracer.intersect(ctx.world.camera.generateRay(px, py), hit);
    }
  return inside / 1024.0;
}

TEST(EmitterPixels, EdgePixelsGetStratifiedRaysThatEstimateTheirCoverage) {
  const SquareView view(true);
  const RenderContext& ctx = view.ctx;
  const EmitterPixels fine(ctx, 16);
  const EmitterPixels single(ctx, 1);
  auto clear = [](const Ray&) { return RGB(1.0f); };
  double fineSq = 0.0, singleSq = 0.0, estimated = 0.0, covered = 0.0;
  int edges = 0, inside = 0;
  uint64_t rays = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const double c = coverage(ctx, x, y);
      inside += c == 1.0;
      if (c > 0.0 && c < 1.0) {
        ++edges;
        EXPECT_TRUE(fine.covers(x, y)) << x << " " << y << " covered " << c;
      }
      if (!fine.covers(x, y)) continue;
      // Four camera samples' worth, as a pixel at 4 spp gets them.
      Rng rng(5, static_cast<uint64_t>(y * 32 + x));
      double fineMean = 0.0, singleMean = 0.0;
      for (int k = 0; k < 4; ++k) {
        fineMean += emissionOf(fine, ctx, x, y, rng, clear, rays).x / 4.0;
        singleMean += emissionOf(single, ctx, x, y, rng, clear, rays).x / 4.0;
      }
      estimated += fineMean;
      covered += 2.0 * c;
      fineSq += (fineMean - 2.0 * c) * (fineMean - 2.0 * c);
      singleSq += (singleMean - 2.0 * c) * (singleMean - 2.0 * c);
    }
  const auto count = static_cast<double>(fine.pixelCount());
  const double fineRms = std::sqrt(fineSq / count), singleRms = std::sqrt(singleSq / count);
  std::printf(
      "%d pixels inside the emitter, %d on its edges, %zu get rays: rms error 16 rays "
      "%.4f, 1 ray %.4f\n",
      inside, edges, fine.pixelCount(), fineRms, singleRms);
  EXPECT_GT(edges, 60);
  // The pixels next to the edge's get them too, but not those inside: there the camera
  // ray's own emission is exact.
  EXPECT_LT(count, 2.5 * edges);
  EXPECT_GT(inside, 150);
  EXPECT_EQ(single.pixelCount(), 0u);  // one ray per sample: the camera ray's own
  // Independent rays would give 1 / 4 of the error; strata along an edge give less still
  // (the error of a stratified estimate of an area falls as N^-3/4).
  EXPECT_LT(fineRms, 0.2 * singleRms);
  // Unbiased: what they estimate is the area they cover, within their noise (about 0.05
  // per pixel, over about 150 of them: 0.6 in the sum).
  EXPECT_NEAR(estimated, covered, 1.5);
}

TEST(EmitterPixels, EachRayIsSeenThroughItsOwnTransmittance) {
  const SquareView view(true);
  const RenderContext& ctx = view.ctx;
  const EmitterPixels fine(ctx, 16);
  uint64_t rays = 0;
  Rng rng(1, 1);
  // The centre pixel lies wholly inside the square (so its camera ray alone would do):
  // every ray meets it.
  EXPECT_FALSE(fine.covers(16, 16));
  const RGB half = emissionOf(
      fine, ctx, 16, 16, rng, [](const Ray&) { return RGB(0.5f); }, rays);
  EXPECT_FLOAT_EQ(half.x, 1.0f);
  EXPECT_EQ(rays, 16u);
  // The transmittance is asked for the segment to the emitter: 3 units ahead.
  float farthest = 0.0f;
  emissionOf(
      fine, ctx, 16, 16, rng,
      [&](const Ray& r) {
        farthest = std::max(farthest, r.tmax);
        return RGB(1.0f);
      },
      rays);
  EXPECT_NEAR(farthest, 3.0f, 0.01f);
}

// A silhouette against the environment gets no rays of its own (emitter_pixels.h).
TEST(EmitterPixels, SilhouettesAgainstTheEnvironmentKeepTheCameraRays) {
  const SquareView view(false);
  const RenderContext& ctx = view.ctx;
  EXPECT_EQ(EmitterPixels(ctx, 16).pixelCount(), 0u);
}

// End to end, pcb at 4 spp: the edge pixels' rays replace the camera rays' emission there
// (not added to it: the image's light stays the lamp's area) and bring its edges closer.
TEST(EmitterPixels, PcbImagesTakeTheEdgesFromTheirRays) {
  const SquareView view(true);
  const RenderContext& ctx = view.ctx;
  const EmitterPixels edges(ctx, 16);
  auto renderWith = [](int samples, Report& report) {
    // Even samples: every edge pixel takes 4 camera samples, each `samples` rays.
    const Scene scene = squareScene(
        true, R"("render": {"mode": "pcb", "spp": 4, "adaptive_spp": 0, "emitter_samples": )" +
                  std::to_string(samples) + "},");
    RenderPlan plan;
    plan.spp = 4;
    return renderScene(scene.job(), plan, report).image;
  };
  Report fineReport, coarseReport;
  const Image fine = renderWith(16, fineReport), coarse = renderWith(1, coarseReport);
  double fineSq = 0.0, coarseSq = 0.0, fineSum = 0.0, covered = 0.0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const double c = 2.0 * coverage(ctx, x, y);
      covered += c;
      fineSum += fine.at(x, y).x;
      if (!edges.covers(x, y)) continue;
      fineSq += (fine.at(x, y).x - c) * (fine.at(x, y).x - c);
      coarseSq += (coarse.at(x, y).x - c) * (coarse.at(x, y).x - c);
    }
  std::printf("edge pixels' rms error: 16 rays %.4f, the camera rays' %.4f; light %.4f of %.4f\n",
              std::sqrt(fineSq / static_cast<double>(edges.pixelCount())),
              std::sqrt(coarseSq / static_cast<double>(edges.pixelCount())), fineSum, covered);
  EXPECT_LT(fineSq, 0.1 * coarseSq);
  EXPECT_NEAR(fineSum, covered, 0.01 * covered);
  EXPECT_EQ(fineReport.counts.at("emitter_rays"), edges.pixelCount() * 4 * 16);
  EXPECT_EQ(coarseReport.counts.count("emitter_rays"), 0u);
}

// The same lamp 2 cm in front of a grey wall (albedo 0.5) that fills the view: the lamp's
// back lights the wall behind it, and the camera sees a bright rim of wall around the
// lamp, a few centimetres wide, falling off with the distance from its edge (a lamp on a
// wall, as in scenes/lamp_hall.json). No other light and nothing else: the image is the
// lamp's emission and the light the wall reflects straight from it.
Scene lampOnWall(const std::string& render = R"("render": {},)") {
  return parseScene(
      std::string(R"({
    "camera": {"position": [0, 0, -3], "look_at": [0, 0, 0], "vfov_deg": 40, "width": 32, "height": 32},)") +
          render + R"("materials": {"lamp": {"albedo": 0, "emission": 2}, "wall": {"albedo": 0.5}},
    "shapes": [{"type": "quad", "corners": [[-0.2, -0.85, -0.02], [0.85, -0.2, -0.02], [0.2, 0.85, -0.02], [-0.85, 0.2, -0.02]], "material": "lamp"},
               {"type": "quad", "corners": [[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]], "material": "wall"}]})",
      "/tmp/emitter-pixels-wall.json");
}

struct WallView {
  Scene scene = lampOnWall();
  RayTracer tracer{scene.world.mesh};
  LightSet lights{scene.world, 16};
  RenderContext ctx{scene.world, scene.render, tracer, lights};
};

// What pixel (x, y) sees straight from the lamp, converged: a 16 x 16 grid of rays over
// the pixel, each the emission it meets (unless `wallOnly`) or the wall's light by 64
// stratified samples.
double seenExactly(const RenderContext& ctx, const LightSet& fine, int x, int y,
                   bool wallOnly = false) {
  const RenderContext withFine{ctx.world, ctx.settings, ctx.tracer, fine, ctx.budget};
  auto clear = [](const Ray&) { return RGB(1.0f); };
  double sum = 0.0;
  uint64_t shadowRays = 0;
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 16; ++i) {
      const float px = static_cast<float>(x) + (static_cast<float>(i) + 0.5f) / 16.0f;
      const float py = static_cast<float>(y) + (static_cast<float>(j) + 0.5f) / 16.0f;
      const Ray ray = ctx.world.camera.generateRay(px, py);
      SurfaceHit hit;
      if (!ctx.tracer.intersect(ray, hit)) continue;
      const Material& m = ctx.world.materials[ctx.world.mesh.triangleMaterial[hit.triangle]];
      Rng rng(17, static_cast<uint64_t>((y * 32 + x) * 256 + j * 16 + i));
      sum += (wallOnly ? 0.0f : m.emission.x) +
             surfaceDirect(withFine, hit, m.albedo, rng, clear, shadowRays).x;
    }
  return sum / 256.0;
}

TEST(EmitterPixels, EdgeRaysTakeTheLightOfTheSurfacesBesideTheEmitter) {
  // The wall's light in the edge pixels of the lamp on the wall: a pixel's 4 camera
  // samples' worth of the edge rays (16 each, 4 light samples each) against the converged
  // value, unbiased (their sum within 3 %: its noise is about 1.1 %) and with an rms error
  // under 0.5 of that of 4 camera rays with 16 light samples each at the ray's own point,
  // what the pixel took before (measured 0.2).
  const WallView view;
  const RenderContext& ctx = view.ctx;
  const LightSet fine(view.scene.world, 64);
  const EmitterPixels edges(ctx, 16);
  ASSERT_EQ(edges.lightSamples(), 4);  // a quarter of area_light_samples' 16
  auto clear = [](const Ray&) { return RGB(1.0f); };
  double edgeSq = 0.0, cameraSq = 0.0, edgeSum = 0.0, exactSum = 0.0;
  uint64_t rays = 0, shadowRays = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      if (!edges.covers(x, y)) continue;
      const double exact = seenExactly(ctx, fine, x, y, true);
      Rng rng(5, static_cast<uint64_t>(y * 32 + x));
      double edge = 0.0, camera = 0.0;
      for (int k = 0; k < 4; ++k) {
        edge += edges.seen(ctx, x, y, rng, clear, clear, LightSubset{}, rays, shadowRays).direct.x /
                4.0;
        const Ray ray = ctx.world.camera.generateRay(static_cast<float>(x) + rng.uniform(),
                                                     static_cast<float>(y) + rng.uniform());
        SurfaceHit hit;
        if (!ctx.tracer.intersect(ray, hit)) continue;
        const Material& m = ctx.world.materials[ctx.world.mesh.triangleMaterial[hit.triangle]];
        camera += surfaceDirect(ctx, hit, m.albedo, rng, clear, shadowRays).x / 4.0;
      }
      edgeSum += edge;
      exactSum += exact;
      edgeSq += (edge - exact) * (edge - exact);
      cameraSq += (camera - exact) * (camera - exact);
    }
  const auto count = static_cast<double>(edges.pixelCount());
  std::printf(
      "the wall in %zu edge pixels: rms error edge rays %.4f, camera rays %.4f; light "
      "%.3f of %.3f\n",
      edges.pixelCount(), std::sqrt(edgeSq / count), std::sqrt(cameraSq / count), edgeSum,
      exactSum);
  EXPECT_LT(edgeSq, 0.5 * 0.5 * cameraSq);
  EXPECT_NEAR(edgeSum, exactSum, 0.03 * exactSum);
}

// End to end, pcb at 4 spp on the lamp on the wall: the edge pixels come out closer to
// the converged values with the edge rays (emitter_samples 16) than without (1), and the
// image's light is the same.
TEST(EmitterPixels, PcbImagesTakeTheWallsRimFromTheEdgeRays) {
  const WallView view;
  const LightSet fine(view.scene.world, 64);
  const EmitterPixels edges(view.ctx, 16);
  auto renderWith = [](int samples) {
    const Scene scene = lampOnWall(R"("render": {"mode": "pcb", "spp": 4, "emitter_samples": )" +
                                   std::to_string(samples) + "},");
    RenderPlan plan;
    plan.spp = 4;
    Report report;
    return renderScene(scene.job(), plan, report).image;
  };
  const Image withRays = renderWith(16), without = renderWith(1);
  double withSq = 0.0, withoutSq = 0.0, withSum = 0.0, exactSum = 0.0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      if (!edges.covers(x, y)) continue;
      const double exact = seenExactly(view.ctx, fine, x, y);
      exactSum += exact;
      withSum += withRays.at(x, y).x;
      withSq += (withRays.at(x, y).x - exact) * (withRays.at(x, y).x - exact);
      withoutSq += (without.at(x, y).x - exact) * (without.at(x, y).x - exact);
    }
  std::printf("edge pixels' rms error: edge rays %.4f, camera rays %.4f; light %.3f of %.3f\n",
              std::sqrt(withSq / static_cast<double>(edges.pixelCount())),
              std::sqrt(withoutSq / static_cast<double>(edges.pixelCount())), withSum, exactSum);
  EXPECT_LT(withSq, 0.25 * withoutSq);
  EXPECT_NEAR(withSum, exactSum, 0.02 * exactSum);
}

}  // namespace
}  // namespace lvox
