// Where the camera samples fall in their pixels (tile_renderer.h, pixelSample): the
// power-of-two prefixes of a pixel's samples are stratified, in every mode. An emissive
// half-plane whose edge crosses a column of pixels at 0.3 of their width is seen with
// N = 4 and 16 samples: each pixel of that column must hold the covered fraction 0.7 to
// within 1/N, which stratified positions guarantee (each of the N columns 1/N wide holds
// one sample) and independent positions miss in about a third of the pixels at N = 4.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"

namespace lvox {
namespace {

// An 8 x 8 camera at the origin looking down -z with a 90 degree field of view: film x
// maps linearly to x on the plane z = -1 (x = 2 px / 8 - 1), so the edge at x = 0.075
// lies at px = 4.3, inside pixel column 4.
constexpr char kScene[] = R"({
  "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0],
             "vfov_deg": 90, "width": 8, "height": 8},
  "materials": {"lamp": {"albedo": 0, "emission": 2}},
  "shapes": [{"type": "quad", "material": "lamp",
              "corners": [[0.075, -5, -1], [5, -5, -1], [5, 5, -1], [0.075, 5, -1]]}],
  "lights": []})";

void expectStratifiedEdge(Mode mode, int spp, uint64_t seed) {
  Scene scene = parseScene(kScene, "/tmp/lvox-pixel-samples.json");
  scene.render.mode = mode;
  scene.render.spp = spp;
  scene.render.seed = seed;
  Report report;
  const Image image = renderScene(scene.job(), report);
  const float emission = 2.0f;
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      const float covered = image.at(x, y).x / emission;
      const float expected = x < 4 ? 0.0f : (x == 4 ? 0.7f : 1.0f);
      EXPECT_NEAR(covered, expected, 1.0f / static_cast<float>(spp) + 1e-4f)
          << "pixel (" << x << ", " << y << "), " << spp << " spp, seed " << seed;
    }
  }
}

TEST(PixelSamples, FourAndSixteenSamplesAreStratifiedInDirectMode) {
  for (uint64_t seed : {1u, 2u, 3u, 4u}) {
    expectStratifiedEdge(Mode::kDirect, 4, seed);
    expectStratifiedEdge(Mode::kDirect, 16, seed);
  }
}

TEST(PixelSamples, FourAndSixteenSamplesAreStratifiedInMonteCarloMode) {
  for (uint64_t seed : {1u, 2u}) {
    expectStratifiedEdge(Mode::kMc, 4, seed);
    expectStratifiedEdge(Mode::kMc, 16, seed);
  }
}

TEST(PixelSamples, FourAndSixteenSamplesAreStratifiedInPointBasedMode) {
  expectStratifiedEdge(Mode::kPcb, 4, 1);
  expectStratifiedEdge(Mode::kPcb, 16, 2);
}

}  // namespace
}  // namespace lvox
