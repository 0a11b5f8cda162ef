// The constant environment's light in the media as harmonics on a grid
// (src/render/environment_cache.h): the projection against closed forms, the
// interpolation, and direct mode with the cache against exact shadow rays.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "render/closed_room.h"
#include "src/render/environment_cache.h"
#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"

namespace lvox {
namespace {

const Bounds3 kBox{{0, 0, 0}, {2, 1, 1}};
const RGB kSky(0.5f, 1.0f, 2.0f);

TEST(EnvironmentCache, TheLatticeCoversTheSphereEvenly) {
  // Its directions average every harmonic above the mean to about zero (here: their sum).
  for (int n : {32, 128}) {
    double sum[kShCoefficients] = {};
    for (int j = 0; j < n; ++j) {
      const Vec3 d = EnvironmentCache::latticeDirection(j, n);
      EXPECT_NEAR(length(d), 1.0f, 1e-6f);
      float y[kShCoefficients];
      shBasis(d, kShCoefficients, y);
      for (int k = 0; k < kShCoefficients; ++k) sum[k] += static_cast<double>(y[k]) / n;
    }
    EXPECT_NEAR(sum[0], 1.0, 1e-12);
    for (int k = 1; k < kShCoefficients; ++k) EXPECT_NEAR(sum[k], 0.0, 2.0 / n) << n << " " << k;
  }
}

TEST(EnvironmentCache, AnOpenSkyIsItsMeanAndNoDirection) {
  const EnvironmentCache cache(kSky, kBox, 4, 128, [](const Ray&) { return RGB(1.0f); });
  RGB c[kShCoefficients];
  cache.lookup({0.7f, 0.3f, 0.9f}, c);
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(c[0][ch], kSky[ch], 1e-5f * kSky[ch]);
  for (int k = 1; k < kShCoefficients; ++k)
    for (int ch = 0; ch < 3; ++ch) EXPECT_LT(std::abs(c[k][ch]), 0.01f * kSky[ch]) << k;
}

// Light from the upper hemisphere only (a ground below): c_0 = L / 2 and the y harmonic
// (sqrt 3) y gives (1 / 4 pi) sqrt 3 pi L = (sqrt 3 / 4) L; every other one vanishes by
// symmetry. The lattice's sharp edge at the horizon costs about 1 % at 128 directions.
TEST(EnvironmentCache, TheUpperHemisphereMatchesItsClosedForm) {
  const EnvironmentCache cache(kSky, kBox, 2, 128,
                               [](const Ray& r) { return RGB(r.dir.y > 0.0f ? 1.0f : 0.0f); });
  RGB c[kShCoefficients];
  cache.lookup({1.0f, 0.5f, 0.5f}, c);
  EXPECT_NEAR(c[0].y, 0.5f, 0.01f);
  EXPECT_NEAR(c[1].y, std::sqrt(3.0f) / 4.0f, 0.01f);
  for (int k : {2, 3, 4, 5, 6, 7, 8}) EXPECT_LT(std::abs(c[k].y), 0.02f) << k;
}

TEST(EnvironmentCache, NodesAreInterpolatedGeometrically) {
  // Transmittance that falls exponentially along x (a homogeneous slab towards every
  // direction) is reproduced exactly between nodes: the mean is interpolated in its
  // logarithm, the direction (coefficients over the mean) trilinearly.
  const EnvironmentCache cache(kSky, kBox, 4, 32, [](const Ray& r) {
    return RGB(std::exp(-2.0f * r.origin.x) * (r.dir.y > 0.0f ? 1.0f : 0.5f));
  });
  RGB at0[kShCoefficients];
  cache.lookup({0.0f, 0.4f, 0.6f}, at0);
  for (float x : {0.3f, 1.1f, 2.0f}) {
    RGB c[kShCoefficients];
    cache.lookup({x, 0.4f, 0.6f}, c);
    EXPECT_NEAR(c[0].y / at0[0].y, std::exp(-2.0f * x), 1e-5f) << x;
    EXPECT_NEAR(c[1].y / c[0].y, at0[1].y / at0[0].y, 1e-5f) << x;
  }
}

TEST(EnvironmentCache, NodesInsideSurfacesAreLeftOut) {
  // The nodes at x = 0 are inside a wall (every shadow ray blocked): a point in the open
  // next to them sees the sky its open neighbours see, not a blend with the wall's dark.
  const EnvironmentCache cache(kSky, kBox, 4, 32,
                               [](const Ray& r) { return RGB(r.origin.x < 0.25f ? 0.0f : 1.0f); });
  RGB c[kShCoefficients];
  cache.lookup({0.2f, 0.4f, 0.6f}, c);
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(c[0][ch], kSky[ch], 1e-5f * kSky[ch]);
  cache.lookup({0.0f, 0.5f, 0.5f}, c);  // on the wall's nodes: nothing
  EXPECT_EQ(c[0], RGB(0.0f));
}

// A cloud lit by the sky alone, 24x24 pixels in direct mode: with the cache, against exact
// shadow rays in random directions (the old path) averaged over many samples.
std::string skyCloud(int cache, int spp) {
  return R"({"camera": {"position": [0, 0.2, 4], "look_at": [0, 0, 0], "vfov_deg": 40, "width": 24, "height": 24},
    "render": {"mode": "direct", "spp": )" +
         std::to_string(spp) + R"(, "seed": 5},
    "lights": [{"type": "environment", "radiance": [0.4, 0.6, 1.0]}],
    "media": [{"type": "procedural", "kind": "gaussian_blob", "center": [0, 0, 0], "radius": 0.5,
               "min": [-1.2, -1.2, -1.2], "max": [1.2, 1.2, 1.2], "sigma_a": 0.3, "sigma_s": 5,
               "g": 0.6, "phase": "hg"}],
    "volume_integrator": {"environment_cache": )" +
         std::to_string(cache) + R"(, "environment_cache_directions": 64}})";
}

double meanOf(const Image& image) {
  double sum = 0.0;
  for (const RGB& p : image.pixels) sum += double(p.x) + p.y + p.z;
  return sum / static_cast<double>(image.pixels.size());
}

TEST(EnvironmentCache, DirectModeConvergesToExactShadowRays) {
  Report exactReport;
  const Image exact =
      renderScene(parseScene(skyCloud(0, 256), "/tmp/sky-cloud.json").job(), exactReport);
  EXPECT_EQ(exactReport.counts["environment_cache_medium_evals"], 0u);
  double error[2];
  for (int i = 0; i < 2; ++i) {
    const int cells = i == 0 ? 6 : 12, spp = i == 0 ? 4 : 64;  // enough rays to build it
    Report report;
    const Image cached =
        renderScene(parseScene(skyCloud(cells, spp), "/tmp/sky-cloud.json").job(), report);
    ASSERT_GT(report.counts["environment_cache_medium_evals"], 0u) << cells;
    for (const RGB& p : cached.pixels)
      ASSERT_TRUE(isFinite(p) && std::min({p.x, p.y, p.z}) >= 0.0f) << cells;
    error[i] = meanOf(cached) / meanOf(exact) - 1.0;
  }
  // Measured +0.18 % at 6 cells across the blob and -0.03 % at 12, at the exact image's own
  // noise (about 0.1 % at 256 spp); interpolating the mean linearly instead of in its
  // logarithm gave +1.35 % and +0.43 % (a convex transmittance overestimated), and the
  // harmonics taken at -viewDir (the wrong side of the phase function) +8.4 %.
  EXPECT_LT(std::abs(error[0]), 0.006);
  EXPECT_LT(std::abs(error[1]), 0.004);
}

// A closed room (2 x 2 x 2) under the sky, with a cloud that its ceiling cuts in half: the
// nodes above the ceiling see the sky, those in the room see none, and no light can enter.
// The fog under the ceiling, seen from inside, must be black. Blending the nodes above the
// ceiling into it lit it (the sunlit gallery's smoke, which its walls and ceiling cut, came
// out 2 % too bright in direct mode for that, docs/results.md, stop 49).
TEST(EnvironmentCache, NoSkyLeaksThroughACeilingThatCutsTheCloud) {
  const std::string walls = test::closedRoomWalls("white");
  const std::string text = R"({
    "camera": {"position": [0, 0.8, -0.9], "look_at": [0, 2, 0.3], "vfov_deg": 60, "width": 16, "height": 16},
    "render": {"mode": "direct", "spp": 8, "seed": 1},
    "materials": {"white": {"albedo": 0.8}},
    "shapes": [)" + walls + R"(],
    "lights": [{"type": "environment", "radiance": [0.4, 0.6, 1.0]}],
    "media": [{"type": "procedural", "kind": "gaussian_blob", "center": [0, 2, 0], "radius": 0.6,
               "min": [-0.9, 1.4, -0.9], "max": [0.9, 2.6, 0.9], "sigma_a": 0.3, "sigma_s": 5}],
    "volume_integrator": {"environment_cache": 8, "environment_cache_directions": 32}})";
  Report report;
  const Image image = renderScene(parseScene(text, "/tmp/sky-leak-test.json").job(), report);
  ASSERT_GT(report.counts["environment_cache_medium_evals"], 0u);
  EXPECT_GT(report.counts["environment_cache_nodes_near_surfaces"], 0u);
  const double mean = meanOf(image);
  std::printf("the closed room's fog under the ceiling: %.3g (sum of colours)\n", mean);
  // Measured 1.1e-4; exact shadow rays (no cache) give 5.3e-5 (rays that slip between
  // the quads at the room's edges). Blending the nodes above the ceiling gave 1.27e-3,
  // and 1.27e-3 still while the nodes on the ceiling's plane went unmarked (their own
  // rays start on it and pass it).
  EXPECT_LT(mean, 4e-4);
}

}  // namespace
}  // namespace lvox
