// --mode pcb-surfels end to end: the point cloud replaces one bounce of indirect light.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "pointcloud/pointcloud_settings.h"
#include "src/core/image_metrics.h"
#include "src/render/layers.h"
#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"

namespace lvox {
namespace {

RenderResult render(const std::string& text, Report& report) {
  Scene scene = parseScene(text, "/tmp/pcb-test.json");
  RenderPlan plan;
  plan.spp = scene.render.spp;
  return renderScene(scene.job(), plan, report);
}

// The scene text with its "MODE" placeholder replaced.
std::string sceneInMode(std::string scene, const std::string& mode) {
  return scene.replace(scene.find("MODE"), 4, mode);
}

// A white floor beside a red wall, lit by a sun that reaches both: the floor next to the
// wall is reddened by light bounced off the wall.
TEST(PointBasedRenderer, RedWallBleedsOntoWhiteFloor) {
  const std::string scene = R"({
    "camera": {"position": [0.25, 0.15, 2], "look_at": [0.25, 0, 0], "vfov_deg": 1, "width": 1, "height": 1},
    "render": {"mode": "MODE", "spp": 4, "max_bounces": 2},
    "materials": {"white": {"albedo": 0.8}, "red": {"albedo": [0.8, 0.05, 0.05]}},
    "shapes": [{"type": "quad", "corners": [[-2,0,-2],[2,0,-2],[2,0,2],[-2,0,2]], "material": "white"},
               {"type": "quad", "corners": [[0,0,-2],[0,0,2],[0,3,2],[0,3,-2]], "material": "red"}],
    "lights": [{"type": "directional", "direction": [-0.5, -0.7, -0.2], "irradiance": 3}],
    "pointcloud": {"surfel_spacing": 0.03, "gather_samples": 1024, "cluster_solid_angle": 0,
                   "bounces": 0, "gather_spacing": 1}
  })";
  auto withMode = [&](const std::string& mode) { return sceneInMode(scene, mode); };
  Report pcbReport, mcReport;
  const RGB pcb = render(withMode("pcb-surfels"), pcbReport).image.at(0, 0);
  // The Monte Carlo reference with the same bounce budget (direct + one bounce).
  Scene mcScene = parseScene(withMode("mc"), "/tmp/pcb-test.json");
  mcScene.render.spp = 4096;
  const RGB mc = renderScene(mcScene.job(), mcReport).at(0, 0);
  // Direct light is white, so the red excess x - y is the bleeding. It must be clearly
  // there and match the reference within 5 % (surfel discretisation and gather noise).
  EXPECT_GT(pcb.x - pcb.y, 0.1f);
  EXPECT_NEAR(pcb.x - pcb.y, mc.x - mc.y, 0.05f * (mc.x - mc.y));
  EXPECT_NEAR(pcb.y, mc.y, 0.02f * mc.y);
  EXPECT_EQ(pcbReport.counts["lvoxels"], 0u);  // no media: no lvoxels
  EXPECT_GT(pcbReport.counts["surfels"], 10000u);
  EXPECT_GT(pcbReport.memory["octree"], 0u);
  // Full pcb mode in a scene without media is the same renderer: no lvoxels, same image.
  Report fullReport;
  const RGB full = render(withMode("pcb"), fullReport).image.at(0, 0);
  EXPECT_EQ(fullReport.counts["lvoxels"], 0u);
  EXPECT_EQ(full, pcb);
  // Gibson's visibility by the first surfel disk (the default traces the real surface and
  // takes its radiance from the cloud): the same bleeding.
  std::string disks = withMode("pcb");
  const std::string bounces = "\"bounces\": 0";
  disks.replace(disks.find(bounces), bounces.size(),
                bounces + ", \"gather_visibility\": \"cloud\"");
  Report disksReport;
  const RGB cloud = render(disks, disksReport).image.at(0, 0);
  EXPECT_NEAR(cloud.x - cloud.y, mc.x - mc.y, 0.05f * (mc.x - mc.y));
  EXPECT_NEAR(cloud.y, mc.y, 0.02f * mc.y);
}

// A lamp (an emissive quad, albedo 0) over a white floor, nothing else: all the floor's
// light is the lamp's direct light, which surfaceDirect samples as an area light. The
// cloud must not carry the lamp's emission too: until stop 25 the lamp's surfels sent it
// into every gather and the floor came out 1.9 times too bright. pcb must equal direct
// mode (the same shadow rays; the only indirect light is the floor's own, none) within
// the gathers' noise on nothing, and well within 1 %.
TEST(PointBasedRenderer, EmissiveSurfacesAreNotCountedTwice) {
  const std::string scene = R"({
    "camera": {"position": [0.5, 1, -1], "look_at": [0.5, 0, 0], "vfov_deg": 1, "width": 1, "height": 1},
    "render": {"mode": "MODE", "spp": 16, "area_light_samples": 64},
    "materials": {"white": {"albedo": 0.7}, "lamp": {"albedo": 0.0, "emission": 12}},
    "shapes": [{"type": "quad", "corners": [[-3,0,-3],[3,0,-3],[3,0,3],[-3,0,3]], "material": "white"},
               {"type": "quad", "corners": [[-0.6,1.5,-0.6],[0.6,1.5,-0.6],[0.6,1.5,0.6],[-0.6,1.5,0.6]], "material": "lamp"}],
    "pointcloud": {"target_surfels": 20000, "gather_spacing": 1}
  })";
  auto withMode = [&](const std::string& mode) { return sceneInMode(scene, mode); };
  Report pcbReport, directReport;
  const RGB pcb = render(withMode("pcb"), pcbReport).image.at(0, 0);
  const RGB direct = render(withMode("direct"), directReport).image.at(0, 0);
  EXPECT_GT(direct.x, 0.1f);
  EXPECT_NEAR(pcb.x, direct.x, 0.01f * direct.x);
}

// A sunlit floor under a roof of slats 0.1 wide and 0.1 apart, a back wall and a red side
// wall: stripes of sun much narrower than the surfel spacing, and slats whose faces have few
// surfels of their own. With traced gathers the sun's light is evaluated at each gather
// hit (delta_hit_light.h), not read from the nearest surfel.
std::string pergola(int surfels, int bounces, const std::string& pointcloud = "") {
  std::string shapes =
      R"({"type": "quad", "corners": [[-3,0,-3],[-3,0,3],[3,0,3],[3,0,-3]], "material": "white"},
         {"type": "quad", "corners": [[-3,0,-3],[3,0,-3],[3,3,-3],[-3,3,-3]], "material": "white"},
         {"type": "quad", "corners": [[-3,0,-3],[-3,3,-3],[-3,3,3],[-3,0,3]], "material": "red"})";
  for (int j = 0; j < 20; ++j) {
    const std::string z0 = std::to_string(-3.0 + 0.2 * j), z1 = std::to_string(-2.9 + 0.2 * j);
    shapes += R"(, {"type": "box", "min": [-3, 2.4, )" + z0 + R"(], "max": [3, 2.5, )" + z1 +
              R"(], "material": "white"})";
  }
  return R"({
    "camera": {"position": [0, 1.2, 2.8], "look_at": [0, 1, -3], "vfov_deg": 60, "width": 48, "height": 32},
    "render": {"spp": 8},
    "materials": {"white": {"albedo": 0.7}, "red": {"albedo": [0.7, 0.2, 0.2]}},
    "shapes": [)" +
         shapes + R"(],
    "lights": [{"type": "directional", "direction": [0.3, -0.9, -0.25], "irradiance": 3}],
    "pointcloud": {"target_surfels": )" +
         std::to_string(surfels) + R"(, "bounces": )" + std::to_string(bounces) +
         R"(, "gather_spacing": 1)" + pointcloud + R"(}
  })";
}

// `evenSamples`: no adaptive samples (render.adaptive_spp 0).
Image renderPergola(const std::string& mode, int surfels, int bounces, int spp, int maxBounces,
                    const std::string& pointcloud = "", Report* report = nullptr,
                    bool evenSamples = false) {
  Scene scene = parseScene(pergola(surfels, bounces, pointcloud), "/tmp/pcb-pergola.json");
  scene.render.mode = parseMode(mode, "test", "mode");
  scene.render.spp = spp;
  if (evenSamples) scene.render.adaptiveSpp = 0;
  scene.render.maxBounces = maxBounces;
  Report own;
  return renderScene(scene.job(), report ? *report : own);
}

TEST(PointBasedRenderer, SunlitGatherHitsDoNotDependOnTheSurfelSpacing) {
  // One bounce (no interreflection passes): the sun is the only light, so every gather
  // hit's light is its own shadow ray's, and 300 surfels give the image 3000 give, bit for
  // bit. It equals MC's direct plus one bounce within the noise of both means (measured
  // 1.006 against 4096 paths). Read from the nearest surfel as before, the sun's light came
  // out 9.4 % too bright at 300 surfels and 1.7 % too dark at 3000.
  const Image coarse = renderPergola("pcb", 300, 0, 8, 2);
  const Image fine = renderPergola("pcb", 3000, 0, 8, 2);
  EXPECT_EQ(compareImages(coarse, fine, "coarse", "fine").maxAbs, 0.0);
  const Image mc = renderPergola("mc", 300, 0, 1024, 2);
  const double mean = compareImages(coarse, mc, "pcb", "mc").meanRatio;
  std::printf("pergola, one bounce: mean against MC %.4f\n", mean);
  EXPECT_NEAR(mean, 1.0, 0.025);
}

TEST(PointBasedRenderer, SunlitSlatsConvergeWithTheCloud) {
  // Every bounce (up to 24 passes and the series' estimated rest, against paths of up to 32
  // events). The surfels carry the light after the first bounce, so the cloud's spacing
  // matters again, but the error falls with it: measured means 0.977, 0.993 and 1.002 at
  // 300, 1000 and 3000 surfels (0.972 and 1.001 at 300 and 3000 since stop 42; before the
  // sun was traced at the hits and the slats' other faces lost the lookup: 1.149, 0.983,
  // 0.965).
  const Image mc = renderPergola("mc", 3000, 24, 1024, 32);
  const double coarse =
      compareImages(renderPergola("pcb", 300, 24, 8, 32), mc, "pcb", "mc").meanRatio;
  const double fine =
      compareImages(renderPergola("pcb", 3000, 24, 8, 32), mc, "pcb", "mc").meanRatio;
  std::printf("pergola, mean against MC: 300 surfels %.4f, 3000 surfels %.4f\n", coarse, fine);
  EXPECT_NEAR(coarse, 1.0, 0.04);
  EXPECT_NEAR(fine, 1.0, 0.015);
  EXPECT_LT(std::abs(fine - 1.0), std::abs(coarse - 1.0));
}

TEST(PointBasedRenderer, TheTriangleLatticeStandsInForTheSearch) {
  // The surfel of each gather hit from the triangle lattice (the default) or from the exact
  // search ("hit_lattice_step": 0), under slats whose two faces lie closer than the
  // spacing: the lattice gives the search's surfel at about 98 % of the hits and a
  // neighbour at the rest (test_triangle_surfel_lattice.cpp), so the images differ by
  // noise. Measured: mean ratio 0.9995, delta 0.74 % (5 rays per surfel side instead of 4
  // move the search's image by 1.8 %; against MC at 1,024 paths both are 8.6 %). Even
  // samples: both images then take the same camera samples, and differ by the surfels
  // alone (with adaptive samples the two images' plans differ too: 1.19 % apart).
  Report latticeReport, searchReport;
  const Image lattice = renderPergola("pcb", 3000, 24, 8, 32, "", &latticeReport, true);
  const Image search =
      renderPergola("pcb", 3000, 24, 8, 32, R"(, "hit_lattice_step": 0)", &searchReport, true);
  const ImageError c = compareImages(lattice, search, "lattice", "search");
  std::printf("pergola, lattice against search: mean %.4f, delta %.3f %%\n", c.meanRatio,
              c.deltaPercent);
  EXPECT_NEAR(c.meanRatio, 1.0, 0.003);
  EXPECT_LT(c.deltaPercent, 1.0);
  // Each holds one of the two, and the report says which.
  EXPECT_GT(latticeReport.memory.count("surfel_lattice"), 0u);
  EXPECT_EQ(latticeReport.memory.count("surfel_lookup"), 0u);
  EXPECT_EQ(searchReport.memory.count("surfel_lattice"), 0u);
  EXPECT_GT(searchReport.memory.count("surfel_lookup"), 0u);
}

// A sunlit wall standing on a sunlit floor, seen from straight above: the floor beside the
// wall's foot takes much of its indirect light from the wall, and less the further out it
// lies. The final-gather grid blends gathers over `gather_filter` grid spacings; every
// fourth pixel (the default until stop 37) blended the corner with floor 12 pixels out and
// left a dark band along it (0.78-0.85 of MC in a canyon scene, docs/results.md). Here,
// against a gather at every hit, the three columns of floor beside the foot hold 0.77 of
// their indirect light with every fourth pixel and 0.91 with every second, the default
// now: it must hold at least 0.85 (the band is not gone; the blend does not know the
// light's gradient), and a finer grid must never hold less.
std::string wallOnFloor(int gatherSpacing) {
  return R"({
    "camera": {"position": [1, 6, 0], "look_at": [1, 0, 0], "up": [0, 0, -1], "vfov_deg": 40, "width": 64, "height": 32},
    "render": {"spp": 4, "max_bounces": 2},
    "materials": {"white": {"albedo": 0.8}},
    "shapes": [{"type": "quad", "corners": [[0,0,-3],[0,0,3],[4,0,3],[4,0,-3]], "material": "white"},
               {"type": "quad", "corners": [[0,0,-3],[0,3,-3],[0,3,3],[0,0,3]], "material": "white"}],
    "lights": [{"type": "directional", "direction": [-0.6, -0.7, -0.2], "irradiance": 3}],
    "pointcloud": {"target_surfels": 20000, "bounces": 0)" +
         (gatherSpacing > 0 ? ", \"gather_spacing\": " + std::to_string(gatherSpacing) : "") +
         R"(}
  })";
}

// The floor's indirect light in the band of columns beside the wall's foot.
double cornerIndirect(const Image& image, const Image& direct) {
  // The image is 8.7 wide at the floor, so the corner (x = 0) falls in column 24.7 and
  // columns 25-27 are floor 0.05-0.45 from the wall (the wall's face fills 17-24).
  double sum = 0.0;
  for (int y = 2; y < 30; ++y)
    for (int x = 25; x <= 27; ++x) sum += image.at(x, y).x - direct.at(x, y).x;
  return sum;
}

TEST(PointBasedRenderer, TheGatherGridKeepsASunlitCornersLight) {
  Report report;
  Scene directScene = parseScene(wallOnFloor(1), "/tmp/pcb-corner.json");
  directScene.render.mode = parseMode("direct", "test", "mode");
  const Image direct = renderScene(directScene.job(), report);
  auto indirect = [&](int gatherSpacing) {
    Report r;
    return cornerIndirect(render(wallOnFloor(gatherSpacing), r).image, direct);
  };
  const double everyHit = indirect(1), byDefault = indirect(0), everyFourth = indirect(4);
  ASSERT_GT(everyHit, 0.0);
  EXPECT_GT(byDefault / everyHit, 0.85);
  EXPECT_LT(byDefault / everyHit, 1.02);
  EXPECT_LT(everyFourth, byDefault);
}

// A lamp (an emissive quad) lights a floor, a red wall and a fog box between them: the
// cloud's direct light is an estimate over the lamp (and the lvoxels' also over the sky),
// `surfel_light_samples` and `lvoxel_light_samples` shadow rays per element. The image
// reads it through the gathers and the lvoxels' interpolation, so it must converge to the
// image of 256 samples as the samples grow (each fourfold at least 0.7 times as far: 0.5
// for independent samples, less for the stratified ones; measured 0.33 and 0.20), with the
// image's mean within 0.5 % already at one sample (measured 0.09 %): the estimate is
// unbiased. The camera's own samples are the same in every render (same seed).
std::string lampRoom(int cacheSamples) {
  const std::string n = std::to_string(cacheSamples);
  return R"({
    "camera": {"position": [0, 1.2, 3.5], "look_at": [0, 0.8, 0], "vfov_deg": 60, "width": 24, "height": 16},
    "render": {"spp": 1, "seed": 3, "area_light_samples": 4},
    "materials": {"white": {"albedo": 0.7}, "red": {"albedo": [0.8, 0.2, 0.2]},
                  "lamp": {"albedo": 0.0, "emission": 8}},
    "shapes": [{"type": "quad", "corners": [[-3,0,-3],[-3,0,3],[3,0,3],[3,0,-3]], "material": "white"},
               {"type": "quad", "corners": [[-1.5,0,-2],[-1.5,2.5,-2],[-1.5,2.5,2],[-1.5,0,2]], "material": "red"},
               {"type": "quad", "corners": [[0,2.4,-0.4],[0.8,2.4,-0.4],[0.8,2.4,0.4],[0,2.4,0.4]], "material": "lamp"}],
    "lights": [{"type": "environment", "radiance": 0.05}],
    "media": [{"type": "homogeneous", "min": [-1, 0.6, -1], "max": [0.2, 1.6, 0.2],
               "sigma_a": 0.1, "sigma_s": 0.9}],
    "pointcloud": {"target_surfels": 20000, "lvoxel_spacing": 0.2, "surfel_light_samples": )" +
         n + R"(, "lvoxel_light_samples": )" + n + R"(}
  })";
}

TEST(PointBasedRenderer, TheCloudsLightSamplesConverge) {
  auto renderWith = [](int samples) {
    Report report;
    return render(lampRoom(samples), report).image;
  };
  const Image reference = renderWith(256);
  double previous = 0.0;
  for (int samples : {1, 4, 16}) {
    const ImageError e = compareImages(renderWith(samples), reference);
    std::printf("%3d samples: rmse %.5f, mean %.5f of 256 samples'\n", samples, e.rmse,
                e.meanRatio);
    EXPECT_GT(e.rmse, 0.0);  // the setting reaches the cloud
    if (samples == 1) {
      EXPECT_NEAR(e.meanRatio, 1.0, 0.005);
    } else {
      EXPECT_LT(e.rmse, 0.7 * previous);
    }
    previous = e.rmse;
  }
}

// A closed room lit by a small lamp under its ceiling, nothing else: the ceiling above the
// lamp is the bright spot the final gathers' cosine rays find by chance. `pointcloud`: the
// scene's "pointcloud" fields beside its 20,000 surfels.
std::string lampLitRoom(int seed, const std::string& pointcloud) {
  return R"({
    "camera": {"position": [0, 2, -5.8], "look_at": [0, 1.6, 0], "vfov_deg": 60, "width": 48, "height": 36},
    "render": {"mode": "pcb", "spp": 4, "max_bounces": 8, "seed": )" +
         std::to_string(seed) + R"(},
    "materials": {"white": {"albedo": 0.7}, "red": {"albedo": [0.7, 0.15, 0.1]},
                  "lamp": {"albedo": 0.0, "emission": 12}},
    "shapes": [{"type": "quad", "corners": [[-3,0,-6],[3,0,-6],[3,0,3],[-3,0,3]], "material": "white"},
               {"type": "quad", "corners": [[-3,4,-6],[3,4,-6],[3,4,3],[-3,4,3]], "material": "white"},
               {"type": "quad", "corners": [[-3,0,3],[3,0,3],[3,4,3],[-3,4,3]], "material": "white"},
               {"type": "quad", "corners": [[-3,0,-6],[3,0,-6],[3,4,-6],[-3,4,-6]], "material": "white"},
               {"type": "quad", "corners": [[-3,0,-6],[-3,0,3],[-3,4,3],[-3,4,-6]], "material": "red"},
               {"type": "quad", "corners": [[3,0,-6],[3,0,3],[3,4,3],[3,4,-6]], "material": "white"},
               {"type": "quad", "corners": [[-0.6,3.7,-0.6],[0.6,3.7,-0.6],[0.6,3.7,0.6],[-0.6,3.7,0.6]], "material": "lamp"}],
    "lights": [],
    "pointcloud": {"target_surfels": 20000)" +
         (pointcloud.empty() ? "" : ", " + pointcloud) + R"(}
  })";
}

// The lamp-lit room's indirect layer, grey (the channels' mean) per pixel.
std::vector<double> lampLitRoomIndirect(int seed, const std::string& pointcloud, Report& report) {
  const Scene parsed = parseScene(lampLitRoom(seed, pointcloud), "/tmp/pcb-test.json");
  RenderPlan plan;
  plan.spp = parsed.render.spp;
  plan.layers = LayerSet::parse("indirect", false, "test");
  const RenderResult result = renderScene(parsed.job(), plan, report);
  std::vector<double> grey;
  for (const ExtraChannel& c : result.layers) {
    if (c.name.rfind("indirect.", 0) != 0) continue;
    grey.resize(c.values.size(), 0.0);
    for (size_t k = 0; k < c.values.size(); ++k) grey[k] += c.values[k] / 3.0;
  }
  return grey;
}

double meanOf(const std::vector<double>& a) {
  double sum = 0.0;
  for (double v : a) sum += v;
  return sum / static_cast<double>(a.size());
}

// The mean absolute difference of two images.
double differenceOf(const std::vector<double>& a, const std::vector<double>& b) {
  double sum = 0.0;
  for (size_t k = 0; k < a.size(); ++k) sum += std::abs(a[k] - b[k]);
  return sum / static_cast<double>(a.size());
}

// Seeds 1-4 of the lamp-lit room with two sets of "pointcloud" fields, a baseline and a
// variant: their indirect layers, reports and means over the four seeds.
struct LampLitRoomPairs {
  std::vector<double> baseline[4], variant[4];
  Report baselineReport[4], variantReport[4];
  double baselineMean = 0.0, variantMean = 0.0;

  LampLitRoomPairs(const std::string& baselineFields, const std::string& variantFields) {
    for (int k = 0; k < 4; ++k) {
      baseline[k] = lampLitRoomIndirect(k + 1, baselineFields, baselineReport[k]);
      variant[k] = lampLitRoomIndirect(k + 1, variantFields, variantReport[k]);
      baselineMean += meanOf(baseline[k]) / 4.0;
      variantMean += meanOf(variant[k]) / 4.0;
    }
  }
  // How much seeds 2 pair + 1 and 2 pair + 2 differ with the variant, over with the baseline.
  double pairRatio(int pair) const {
    const double ratio = differenceOf(variant[2 * pair], variant[2 * pair + 1]) /
                         differenceOf(baseline[2 * pair], baseline[2 * pair + 1]);
    std::printf(
        "seeds %d and %d: the variant's indirect light differs by %.4f of its mean, %.2f "
        "times the baseline's\n",
        2 * pair + 1, 2 * pair + 2,
        differenceOf(variant[2 * pair], variant[2 * pair + 1]) / baselineMean, ratio);
    return ratio;
  }
};

// A quarter of the final gathers' rays at the lit surfaces' cells
// (pointcloud/gather_light_cells.h) must keep the lamp-lit room's indirect light and lose
// noise. Seeds 1-4 build the same cloud either way and the gathers draw their own random
// numbers, so the indirect layers of a seed differ by the final gathers' noise only: over
// seeds 1-32 a seed's two means differ by 0.8 % (standard deviation; mean difference
// -0.23 +- 0.14 %). Over four seeds they must agree within 1.6 %, four standard errors;
// counting the cells' rays' share twice (cosine rays at full weight) comes out 19 % too
// bright. The two seeds of a pair must differ by less with the cells (measured 0.75 and
// 0.85 of the cosine rays' difference, 0.86 and 0.86 with stop 57's burial reach; asserted
// below 0.9). All at 64 rays per gather.
// (The cloud as these were measured: 4 rays per surfel side, the default until stop 57.)
TEST(PointBasedRenderer, TheLitCellsKeepALampLitRoomAndCutItsNoise) {
  const std::string cloud = R"("surfel_gather_samples": 4, )";
  const std::string cells = cloud + R"("gather_samples": 64, "gather_light_samples": 16)";
  const LampLitRoomPairs room(cloud + R"("gather_samples": 64)", cells);
  for (int k = 0; k < 4; ++k) {
    ASSERT_EQ(room.baseline[k].size(), 48u * 36u);
    EXPECT_EQ(room.baselineReport[k].counts.count("gather_light_cells"), 0u);
    EXPECT_GT(room.variantReport[k].counts.at("gather_light_cells"), 1000u);
  }
  std::printf("lamp-lit room: indirect light %.5f (cosine rays), %+.3f %% with the cells\n",
              room.baselineMean, 100.0 * (room.variantMean / room.baselineMean - 1.0));
  EXPECT_NEAR(room.variantMean, room.baselineMean, 0.016 * room.baselineMean);
  for (int pair = 0; pair < 2; ++pair) EXPECT_LT(room.pairRatio(pair), 0.9) << pair;
  // Deterministic: the same seed gives the same image.
  Report again;
  EXPECT_EQ(lampLitRoomIndirect(1, cells, again), room.variant[0]);
}

// "gather_samples": "auto" (the default) in the lamp-lit room. Its 48 x 36 image has 475 grid
// points (every second pixel and one past the last) and its cloud's gathers trace 2 sides x
// 4 rays for each of its 20,600-21,000 surfels (seeds 1-4), so the final gathers get
// ceil(about 166,000 / 475) = 350-355 rays, rounded up to 352 or 368, where a fixed count
// would give 64. The final gathers' share of the noise between seeds falls about
// sqrt(64 / 360) = 0.42 times; the cloud's does not. Measured: the seeds' difference is 0.42
// and 0.51 of 64 rays' (0.38 and 0.46 with stop 57's burial reach), asserted below 0.65. The
// means: over seeds 1-96 auto's is 0.34 +- 0.06 % below 64 rays' (a seed's own difference
// varies by 0.59 %, so four seeds' mean by 0.3 %); asserted within 1 %. Most of that is the
// interleaved quarters' lean at 64 rays, which falls with the rays (without the quarters:
// 0.06 +- 0.08 %; docs/results.md, stop 47). The cloud is pinned at 4 rays per surfel side
// (the default until stop 57; at 8 the final gathers reach the cap of 512).
TEST(PointBasedRenderer, AutoFinalGatherRaysFollowTheCloudsRays) {
  const LampLitRoomPairs room(R"("surfel_gather_samples": 4, "gather_samples": 64)",
                              R"("surfel_gather_samples": 4)");
  for (int k = 0; k < 4; ++k) {
    const Report& fixed = room.baselineReport[k];
    const Report& automatic = room.variantReport[k];
    EXPECT_EQ(fixed.settings.at("final_gather_samples"), "64");
    const uint64_t points = automatic.counts.at("grid_gathers");
    const uint64_t cloudRays = automatic.counts.at("cache_gather_rays");
    EXPECT_EQ(points, 475u);
    // Counted, not timed: the same for every seed and thread count.
    PointCloudSettings four;
    four.surfelGatherSamples = 4;
    const int rays = finalGatherSamples(four, cloudRays, points);
    EXPECT_EQ(automatic.settings.at("final_gather_samples"), std::to_string(rays));
    EXPECT_EQ(automatic.counts.at("grid_gather_rays"), points * static_cast<uint64_t>(rays));
    EXPECT_TRUE(rays == 352 || rays == 368) << rays << " from " << cloudRays;
  }
  std::printf("lamp-lit room: indirect light %.5f (64 rays), %.5f (auto)\n", room.baselineMean,
              room.variantMean);
  EXPECT_NEAR(room.variantMean, room.baselineMean, 0.01 * room.baselineMean);
  for (int pair = 0; pair < 2; ++pair) EXPECT_LT(room.pairRatio(pair), 0.65) << pair;
}

}  // namespace
}  // namespace lvox
