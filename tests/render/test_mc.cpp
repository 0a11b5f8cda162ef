// --mode mc against closed forms. Tolerances are confidence bounds from the sample
// variance of the pixels (each pixel is an independent estimate), not fudge factors.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

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
  return renderScene(scene.job(), report);
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

namespace lvox {
namespace {

// White furnace (oracles 2.4): an albedo-1 medium of any density in a uniform environment
// leaves L = Lenv everywhere. Needs all bounces: scatterings grow like tau^2.
TEST(MonteCarloMedia, WhiteFurnaceWithTheSmokeVdb) {
  const std::string text =
      std::string(R"({"camera": {"position": [0, 3, -6], "look_at": [0, 3, 0],
        "vfov_deg": 40, "width": 16, "height": 16},
      "render": {"mode": "mc", "spp": 16, "max_bounces": 65536, "seed": 3},
      "lights": [{"type": "environment", "radiance": 0.5}],
      "media": [{"type": "vdb", "file": ")") +
      LVOX_SOURCE_DIR + R"(/assets/smoke_plume.vdb", "density_scale": 8, "albedo": 1, "g": 0.4}]})";
  Scene scene = parseScene(text, "/tmp/white-furnace.json");
  Report report;
  const Image image = renderScene(scene.job(), report);
  const PixelStats s = channelStats(image, 1);
  EXPECT_NEAR(s.mean, 0.5, 4.5 * s.standardError + 1e-6) << "se " << s.standardError;
  EXPECT_LT(s.standardError, 0.01);
  EXPECT_GT(report.counts["medium_evals"], 1000u);
}

// MC restricted to single scattering (max_bounces 1) against the closed form of the slab
// (oracles 2.1), which the direct-mode ODE renderer also matches.
TEST(MonteCarloMedia, SingleScatteringMatchesTheSlabOracle) {
  const std::string text = R"({
    "camera": {"position": [-5, 0.5, 0], "look_at": [1, 0.5, 0], "vfov_deg": 0.001, "width": 8, "height": 8},
    "render": {"mode": "mc", "spp": 512, "max_bounces": 1, "seed": 5},
    "lights": [{"type": "directional", "direction": [0.6, -0.8, 0], "irradiance": 2}],
    "media": [{"type": "homogeneous", "min": [-50, 0, -50], "max": [50, 1, 50],
               "sigma_a": 0.05, "sigma_s": 0.1, "g": 0.5, "phase": "hg"}]})";
  const double sigmaT = 0.15, sigmaS = 0.1, g = 0.5, cosTheta = -0.6, s0 = 0.5 / 0.8, d = 55.0;
  const double p = (1 - g * g) / (4 * M_PI * std::pow(1 + g * g - 2 * g * cosTheta, 1.5));
  const double expected =
      sigmaS * p * 2.0 * std::exp(-sigmaT * s0) * (1 - std::exp(-sigmaT * d)) / sigmaT;
  Scene scene = parseScene(text, "/tmp/mc-slab.json");
  Report report;
  const PixelStats s = channelStats(renderScene(scene.job(), report), 0);
  EXPECT_NEAR(s.mean, expected, 4.5 * s.standardError) << "se " << s.standardError;
  EXPECT_LT(s.standardError, 0.03 * expected);
}

// The majorant grid and a single global majorant are both unbiased: same mean.
TEST(MonteCarloMedia, GlobalAndGridMajorantsAgree) {
  const std::string base = std::string(R"({"camera": {"position": [0, 3, -6], "look_at": [0, 3, 0],
        "vfov_deg": 40, "width": 16, "height": 16},
      "render": {"mode": "mc", "spp": 16, "max_bounces": 4, "seed": 11},
      "lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 3}],
      "volume_integrator": {"majorant": "MAJ"},
      "media": [{"type": "vdb", "file": ")") +
                           LVOX_SOURCE_DIR +
                           R"(/assets/smoke_plume.vdb", "density_scale": 6, "albedo": 0.8}]})";
  PixelStats stats[2];
  uint64_t lookups[2];
  int k = 0;
  for (const char* maj : {"grid", "global"}) {
    std::string t = base;
    t.replace(t.find("MAJ"), 3, maj);
    Scene scene = parseScene(t, "/tmp/maj.json");
    Report report;
    stats[k] = channelStats(renderScene(scene.job(), report), 0);
    lookups[k++] = report.counts["medium_evals"];
  }
  const double se = std::hypot(stats[0].standardError, stats[1].standardError);
  EXPECT_NEAR(stats[0].mean, stats[1].mean, 4.5 * se);
  EXPECT_LT(lookups[0], lookups[1]);  // the grid skips null collisions in thin smoke
}

// Image position (pixels) of a point in front of the camera (the inverse of generateRay).
Vec3 projectToImage(const Camera& cam, const Vec3& p) {
  const Vec3 forward = normalize(cam.lookAt - cam.position);
  const Vec3 right = normalize(cross(forward, cam.up));
  const Vec3 trueUp = cross(right, forward);
  const float tanHalf = std::tan(0.5f * cam.vfovDeg * kPi / 180.0f);
  const float aspect = static_cast<float>(cam.width) / static_cast<float>(cam.height);
  const Vec3 d = p - cam.position;
  const float sx = dot(d, right) / dot(d, forward), sy = dot(d, trueUp) / dot(d, forward);
  return {(sx / (tanHalf * aspect) + 1.0f) * 0.5f * static_cast<float>(cam.width),
          (1.0f - sy / tanHalf) * 0.5f * static_cast<float>(cam.height), dot(d, forward)};
}

// MC restricted to single scattering (max_bounces 1) and the ODE single-scattering
// renderer (--mode direct, rk4 at a quarter of the scene's step, equiangular steps around
// point and spot lights) estimate the same image on every hard case. Per pixel the
// difference is the noise of both plus the ODE's bias, so the mean difference over the
// image must be within 4.5 standard errors of it (the scene's own structure cancels) plus
// 1 % of the image mean for the ODE's discretisation.
// The pixels around a point or spot light seen by the camera are left out: a ray passing
// at distance h from the light collects ~1/h, so over the pixel the second moment of any
// estimator diverges (logarithmically) and neither mean is reliable there. Measured with
// 16 ODE and 4096 MC samples, the light's pixel read 6.8 vs 2.5 while single rays agree
// within 1 %; with those pixels in, MC came out 10-12 % lower than the ODE.
TEST(MonteCarloMedia, SingleScatteringAgreesWithTheOdeRendererOnTheHardCases) {
  for (const char* name : {"fog_slab", "point_light_fog", "sharp_shadow", "thick_medium",
                           "thin_beam", "high_frequency"}) {
    const Scene base = loadScene(std::string(LVOX_SOURCE_DIR) + "/scenes/hard/" + name + ".json");
    Scene ode = base, mc = base;
    for (Scene* s : {&ode, &mc}) s->world.camera.width = s->world.camera.height = 16;
    ode.render.mode = Mode::kDirect;
    ode.render.spp = 16;
    ode.volume.solver = rte::Method::kRk4;
    ode.volume.scaleStep(0.25f);
    ode.volume.sampling = rte::Sampling::kEquiangular;
    mc.render.mode = Mode::kMc;
    mc.render.spp = 4096;
    mc.render.maxBounces = 1;
    std::vector<Vec3> lightPixels;
    for (const Light& l : base.world.lights)
      if (l.type == LightType::Point || l.type == LightType::Spot) {
        const Vec3 q = projectToImage(ode.world.camera, l.position);
        if (q.z > 0.0f) lightPixels.push_back(q);
      }
    Report odeReport, mcReport;
    const Image a = renderScene(ode.job(), odeReport);
    const Image b = renderScene(mc.job(), mcReport);
    double sum = 0.0, sum2 = 0.0, level = 0.0, n = 0.0;
    for (int y = 0; y < a.height; ++y)
      for (int x = 0; x < a.width; ++x) {
        bool nearLight = false;
        for (const Vec3& q : lightPixels)
          nearLight = nearLight || (std::abs(static_cast<float>(x) + 0.5f - q.x) < 2.0f &&
                                    std::abs(static_cast<float>(y) + 0.5f - q.y) < 2.0f);
        if (nearLight) continue;
        for (int c = 0; c < 3; ++c) {
          const double d = static_cast<double>(b.at(x, y)[c]) - a.at(x, y)[c];
          sum += d;
          sum2 += d * d;
          level += a.at(x, y)[c];
          n += 1.0;
        }
      }
    const double mean = sum / n;
    const double se = std::sqrt(std::max(0.0, (sum2 - n * mean * mean) / (n - 1.0)) / n);
    EXPECT_NEAR(mean, 0.0, 4.5 * se + 0.01 * level / n)
        << name << ": se " << se << ", image mean " << level / n;
    EXPECT_GT(n, 0.8 * 3.0 * 256.0) << name;  // at most a few pixels left out
  }
}

}  // namespace
}  // namespace lvox

namespace lvox {
namespace {

// sigma_a = 1e9, inside the documented range: exponential steps of 1e-9 units five units from
// the camera round to nothing in float, and the path used to spin on the box's boundary.
// Every step now advances at least one ulp: the box is black, the environment around it 1.
TEST(MonteCarloMedia, AnOpaqueHomogeneousMediumEndsAndIsBlack) {
  const Scene scene = parseScene(R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "vfov_deg": 40, "width": 8, "height": 8},
    "render": {"mode": "mc", "spp": 4},
    "lights": [{"type": "environment", "radiance": 1}, {"type": "point", "position": [0, 0, 0], "intensity": 1}],
    "media": [{"type": "homogeneous", "min": [-1, -1, -1], "max": [1, 1, 1], "sigma_a": 1e9, "sigma_s": 0}]})",
                                 "/tmp/opaque.json");
  Report report;
  const Image image = renderScene(scene.job(), report);
  EXPECT_NEAR(image.at(4, 4).x, 0.0f, 1e-6f);  // through the box's centre
  EXPECT_NEAR(image.at(0, 0).x, 1.0f, 1e-6f);  // the corner sees the environment
}

}  // namespace
}  // namespace lvox
