// Emitters seen directly: which pixels get rays of their own, and what those rays estimate.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "src/render/emitter_pixels.h"
#include "src/render/renderer.h"
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
        fineMean += fine.emission(ctx, x, y, rng, clear, rays).x / 4.0;
        singleMean += single.emission(ctx, x, y, rng, clear, rays).x / 4.0;
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
  const RGB half = fine.emission(
      ctx, 16, 16, rng, [](const Ray&) { return RGB(0.5f); }, rays);
  EXPECT_FLOAT_EQ(half.x, 1.0f);
  EXPECT_EQ(rays, 16u);
  // The transmittance is asked for the segment to the emitter: 3 units ahead.
  float farthest = 0.0f;
  fine.emission(
      ctx, 16, 16, rng,
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
    const Scene scene =
        squareScene(true, R"("render": {"mode": "pcb", "spp": 4, "emitter_samples": )" +
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

}  // namespace
}  // namespace lvox
