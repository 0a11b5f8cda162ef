// --mode mc against closed forms. Tolerances are confidence bounds from the sample
// variance of the pixels (each pixel is an independent estimate), not fudge factors.
#include <gtest/gtest.h>

#include <cmath>

#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"

namespace lvox {
namespace {

struct PixelStats {
  double mean = 0.0;
  double standardError = 0.0;
};

PixelStats channelStats(const Image& image, int c) {
  double sum = 0.0, sum2 = 0.0;
  for (const RGB& p : image.pixels) {
    sum += p[c];
    sum2 += static_cast<double>(p[c]) * p[c];
  }
  const double n = static_cast<double>(image.pixels.size());
  PixelStats s;
  s.mean = sum / n;
  const double variance = std::max(0.0, (sum2 - n * s.mean * s.mean) / (n - 1.0));
  s.standardError = std::sqrt(variance / n);
  return s;
}

// Inside a closed box whose walls have albedo rho and emit Le, radiance is uniform:
// L = Le / (1 - rho) with all bounces (pbrt's furnace test), Le (1 + rho) with one.
Image renderFurnace(int maxBounces, int spp) {
  const std::string text = R"({"camera": {"position": [0.1, 0.2, 0.3], "look_at": [1, 0.5, 2],
        "vfov_deg": 90, "width": 24, "height": 24},
      "render": {"mode": "mc", "spp": )" +
                           std::to_string(spp) + R"(, "max_bounces": )" +
                           std::to_string(maxBounces) + R"(, "seed": 7},
      "materials": {"wall": {"albedo": 0.5, "emission": 0.5}},
      "shapes": [{"type": "box", "min": [-2, -1, -3], "max": [2, 1.5, 3], "material": "wall"}]})";
  Scene scene = parseScene(text, "/tmp/furnace.json");
  Report report;
  return renderScene(scene, report);
}

TEST(MonteCarlo, SurfaceFurnaceAllBounces) {
  const Image image = renderFurnace(1000, 16);
  for (int c = 0; c < 3; ++c) {
    const PixelStats s = channelStats(image, c);
    // 4.5 standard errors: a false failure has probability < 1e-5.
    EXPECT_NEAR(s.mean, 1.0, 4.5 * s.standardError + 1e-6) << "se " << s.standardError;
    EXPECT_LT(s.standardError, 0.02);  // the test has power: it resolves 2%
  }
}

TEST(MonteCarlo, SurfaceFurnaceSingleScattering) {
  const Image image = renderFurnace(1, 8);
  const PixelStats s = channelStats(image, 0);
  EXPECT_NEAR(s.mean, 0.75, 4.5 * s.standardError + 1e-6) << "se " << s.standardError;
  const Image none = renderFurnace(0, 1);
  EXPECT_NEAR(channelStats(none, 0).mean, 0.5, 1e-6);  // emission only
}

TEST(MonteCarlo, ErrorFallsAsInverseSqrtSpp) {
  // RMS error against the exact furnace value at 4 and 64 spp: ratio sqrt(16) = 4.
  auto rms = [](const Image& image) {
    double e2 = 0.0;
    for (const RGB& p : image.pixels) e2 += (p.x - 1.0) * (p.x - 1.0);
    return std::sqrt(e2 / static_cast<double>(image.pixels.size()));
  };
  const double low = rms(renderFurnace(1000, 4)), high = rms(renderFurnace(1000, 64));
  // With 576 pixels the RMS itself is known to ~3% (chi-square), so the ratio to ~6%.
  EXPECT_NEAR(low / high, 4.0, 0.6);
}

}  // namespace
}  // namespace lvox
