// Lat-long environment maps in every mode against closed forms: a Lambertian plane of
// albedo rho whose normal makes the angle alpha with the zenith, under a sky of radiance L
// above the horizon and black below, receives E = pi L (1 + cos alpha) / 2 (the sky's view
// factor) and shows rho E / pi; under a uniform map (a furnace) it shows rho L.
#include <gtest/gtest.h>

#include "src/core/error.h"
#include "src/core/image_io.h"
#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"
#include "test_util.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

// An 8 x 4 map: rows 0-1 (above the horizon) `sky`, rows 2-3 `ground`.
void writeMap(const fs::path& path, float sky, float ground) {
  Image map(8, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) map.at(x, y) = RGB(y < 2 ? sky : ground);
  writeExr(path.string(), map);
}

// A 2 x 2 quad of albedo 0.5 through the origin, facing +y (horizontal) or +z (vertical),
// filling the middle of a 32 x 32 image seen along its normal from 10 units.
Scene quadUnderMap(const fs::path& dir, bool horizontal) {
  const std::string corners = horizontal ? "[[-1,0,-1],[1,0,-1],[1,0,1],[-1,0,1]]"
                                         : "[[-1,-1,0],[1,-1,0],[1,1,0],[-1,1,0]]";
  const std::string camera =
      horizontal ? R"("position": [0, 10, 0], "up": [0, 0, -1])" : R"("position": [0, 0, 10])";
  test::writeFile(dir / "scene.json", R"({"camera": {)" + camera + R"(, "look_at": [0, 0, 0],
      "vfov_deg": 22.6, "width": 32, "height": 32},
    "render": {"spp": 16, "max_bounces": 2, "area_light_samples": 8},
    "materials": {"grey": {"albedo": 0.5}},
    "shapes": [{"type": "quad", "corners": )" +
                                          corners + R"(, "material": "grey"}],
    "lights": [{"type": "environment", "file": "sky.exr"}]})");
  return loadScene((dir / "scene.json").string());
}

// Mean of the central 12 x 12 pixels (all on the quad) and of one corner pixel (the map).
void renderMeans(const Scene& scene, Mode mode, double& quad, float& corner) {
  Scene s = scene;
  s.render.mode = mode;
  // A path's bounce off the quad and its light samples of a half-black map make MC's
  // pixels noisier than the other modes': over seeds its mean of the 144 pixels spreads
  // by 1.6 % at 16 spp (a 2 % bound would be 1.2 sigma) and by 0.5 % at 128.
  if (mode == Mode::kMc) s.render.spp = 128;
  Report report;
  const Image image = renderScene(s.job(), report);
  quad = 0.0;
  for (int y = 10; y < 22; ++y)
    for (int x = 10; x < 22; ++x) quad += image.at(x, y)[0];
  quad /= 144.0;
  corner = image.at(0, 0)[0];
}

TEST(EnvironmentMapRender, FurnaceUniformMap) {
  const fs::path dir = test::tempDir();
  writeMap(dir / "sky.exr", 1.5f, 1.5f);
  const Scene scene = quadUnderMap(dir, true);
  for (Mode mode : {Mode::kDirect, Mode::kPcb, Mode::kMc}) {
    double quad;
    float corner;
    renderMeans(scene, mode, quad, corner);
    // 144 pixels x 16 spp x 8 light samples (MC 128 spp): 2 % is 4 sigma and more.
    EXPECT_NEAR(quad, 0.5 * 1.5, 0.02 * 0.75) << modeName(mode);
    EXPECT_NEAR(corner, 1.5f, 1e-6f) << "camera rays that miss see the map";
  }
}

TEST(EnvironmentMapRender, SkyViewFactorOfHorizontalAndVerticalPlanes) {
  const fs::path dir = test::tempDir();
  writeMap(dir / "sky.exr", 2.0f, 0.0f);
  for (bool horizontal : {true, false}) {
    const Scene scene = quadUnderMap(dir, horizontal);
    // rho L (1 + cos alpha) / 2: alpha = 0 gives 1.0, alpha = 90 degrees 0.5.
    const double expected = 0.5 * 2.0 * (horizontal ? 1.0 : 0.5);
    for (Mode mode : {Mode::kDirect, Mode::kPcb, Mode::kMc}) {
      double quad;
      float corner;
      renderMeans(scene, mode, quad, corner);
      EXPECT_NEAR(quad, expected, 0.02 * expected)
          << modeName(mode) << (horizontal ? " horizontal" : " vertical");
    }
  }
}

TEST(EnvironmentMapRender, UnreadableMapNamesTheField) {
  const fs::path dir = test::tempDir();
  test::writeFile(dir / "sky.exr", "not an image");
  try {
    quadUnderMap(dir, true);
    FAIL() << "an unreadable map was accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("lights[0].file"), std::string::npos) << msg;
    EXPECT_NE(msg.find("sky.exr"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace lvox
