// The shadow transmittance cache of direct mode (volume_integrator.shadow_cache).
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "src/core/image_metrics.h"
#include "src/render/renderer.h"
#include "src/render/transmittance_cache.h"
#include "src/scene/scene_loader.h"

namespace lvox {
namespace {

TEST(TransmittanceCache, InterpolatesAnExponentialFalloffExactly) {
  // A slab y < 1 of sigma 2 lit from above at 60 degrees: T(x) = exp(-2 (1 - y) / cos).
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = normalize(Vec3(std::sqrt(3.0f), -1.0f, 0.0f));  // 30 degrees above the horizon
  const float cosine = -sun.direction.y;
  const auto exact = [&](const Vec3& p) { return std::exp(-2.0f * (1.0f - p.y) / cosine); };
  Bounds3 box;
  box.lo = Vec3(0.0f, 0.0f, 0.0f);
  box.hi = Vec3(1.0f, 1.0f, 1.0f);
  const int resolution = 16;
  const TransmittanceCache cache({sun}, box, resolution, [&](const Ray& ray) {
    EXPECT_EQ(ray.dir, -sun.direction);
    return RGB(exact(ray.origin));
  });
  // Interpolated in its logarithm, an exponential falloff is exact between nodes (linearly
  // it was off by up to h^2 / 8 max |T''|, 1.6e-3 here).
  for (float y = 0.013f; y < 1.0f; y += 0.031f) {
    const Vec3 p(0.37f, y, 0.61f);
    EXPECT_NEAR(cache.lookup(0, p).x, exact(p), 2e-5f * exact(p)) << y;
  }
  // At a node the value is the solved one.
  EXPECT_FLOAT_EQ(cache.lookup(0, Vec3(0.5f, 0.5f, 0.5f)).x, exact(Vec3(0.5f, 0.5f, 0.5f)));
}

Image renderSmoke(int shadowCache, Report& report) {
  std::ostringstream s;
  s << R"({"camera": {"position": [0, 3, -8], "look_at": [0, 3, 0], "vfov_deg": 40, "width": 48, "height": 48},
    "render": {"spp": 4, "mode": "direct"},
    "lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 3},
               {"type": "point", "position": [2, 5, -1], "intensity": 20}],
    "media": [{"type": "vdb", "file": ")"
    << LVOX_SOURCE_DIR
    << R"(/assets/smoke_plume.vdb", "density_scale": 3, "albedo": 0.9, "g": 0.3}],
    "volume_integrator": {"shadow_cache": )"
    << shadowCache << "}}";
  const Scene scene = parseScene(s.str(), "/tmp/shadow-cache.json");
  return renderScene(scene.job(), report);
}

TEST(TransmittanceCache, DirectModeMatchesExactShadowRaysForAFractionOfTheWork) {
  Report exactReport, cachedReport;
  const Image exact = renderSmoke(0, exactReport);
  const Image cached = renderSmoke(64, cachedReport);
  const ImageError e = compareImages(cached, exact);
  // A point light 2 units from the smoke, where T turns fastest.
  // Stop 28: 0.32 %, mean 0.9978, interpolating T in its logarithm (linearly, a convex T was
  // overestimated: 0.79 %, mean 1.0071).
  EXPECT_LT(e.deltaPercent, 0.6);
  EXPECT_NEAR(e.meanRatio, 1.0, 0.005);
  // The camera rays' own work falls by the shadow rays; the cache is a fixed cost (its
  // nodes), built because 48 x 48 x 4 camera rays x 16 exceed them.
  const uint64_t exactEvals = exactReport.counts["medium_evals"];
  const uint64_t cachedEvals = cachedReport.counts["medium_evals"];
  EXPECT_GT(cachedReport.counts["shadow_cache_medium_evals"], 0u);
  EXPECT_LT(cachedEvals * 5, exactEvals) << cachedEvals << " vs " << exactEvals;
  EXPECT_GT(cachedReport.memory["shadow_cache"], 0u);
}

TEST(TransmittanceCache, ASmallRenderSolvesItsShadowRays) {
  // 24 x 24 x 1 camera rays x 16 < the smoke's 70 k nodes: the cache would not pay.
  Report report;
  std::ostringstream s;
  s << R"({"camera": {"position": [0, 3, -8], "look_at": [0, 3, 0], "width": 24, "height": 24},
    "render": {"spp": 1, "mode": "direct"},
    "lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 3}],
    "media": [{"type": "vdb", "file": ")"
    << LVOX_SOURCE_DIR << R"(/assets/smoke_plume.vdb", "density_scale": 3, "albedo": 0.9}]})";
  (void)renderScene(parseScene(s.str(), "/tmp/small.json").job(), report);
  EXPECT_EQ(report.counts["shadow_cache_medium_evals"], 0u);
  EXPECT_EQ(report.memory.count("shadow_cache"), 0u);
}

}  // namespace
}  // namespace lvox
