// Every solver on every hard-case scene of scenes/hard, at a coarse and a fine step: no
// NaN, Inf or negative radiance may reach a pixel (the renderer counts and zeroes such
// samples as invalid_samples, so that count must stay 0), and explicit methods whose step
// is beyond their stability limit in the optically thick medium must detect it.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"

namespace lvox {
namespace {

const char* const kSolvers[] = {"auto",
                                "euler",
                                "rk2",
                                "rk4",
                                "ab4",
                                "backward-euler",
                                "trapezoid",
                                "trapezoid-pc",
                                "rk12",
                                "bs23",
                                "rkf45",
                                "cashkarp",
                                "dopri5",
                                "verner56",
                                "rectangle",
                                "simpson",
                                "adaptive-simpson",
                                "gauss-kronrod",
                                "monte-carlo"};

TEST(HardCases, NoSolverProducesInvalidRadianceAtAnyStep) {
  const std::filesystem::path dir = std::filesystem::path(LVOX_SOURCE_DIR) / "scenes" / "hard";
  std::set<std::string> scenes;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.path().extension() == ".json") scenes.insert(entry.path().string());
  ASSERT_EQ(scenes.size(), 6u);
  for (const std::string& path : scenes) {
    const Scene base = loadScene(path);
    for (const char* solver : kSolvers) {
      for (const float stepScale : {4.0f, 0.5f}) {
        Scene scene = base;
        scene.world.camera.width = scene.world.camera.height = 6;
        scene.render.spp = 1;
        scene.volume.solver = parseSolver(solver, "test", "solver");
        scene.volume.scaleStep(stepScale);
        Report report;
        const Image image = renderScene(scene.job(), report);
        const std::string what = path + " " + solver + " step x" + std::to_string(stepScale);
        EXPECT_EQ(report.counts["invalid_samples"], 0u) << what;
        for (const RGB& p : image.pixels) {
          ASSERT_TRUE(isFinite(p)) << what;
          ASSERT_GE(std::min({p.x, p.y, p.z}), 0.0f) << what;
        }
        // sigma_t = 50 with h = 0.4: far beyond every explicit method's limit.
        const bool explicitRk = std::string(solver) == "euler" || std::string(solver) == "rk4";
        if (path.ends_with("thick_medium.json") && explicitRk && stepScale > 1.0f) {
          EXPECT_GT(report.counts["stability_events"], 0u) << what;
        }
      }
    }
    // The point-based renderer on the same scene (lvoxels, interreflection, grid gathers).
    Scene scene = base;
    scene.world.camera.width = scene.world.camera.height = 6;
    scene.render.spp = 1;
    scene.render.mode = Mode::kPcb;
    scene.pointcloud.targetSurfels = 2000;  // the floors are large and simple
    scene.pointcloud.bounces = 2;
    Report report;
    const Image image = renderScene(scene.job(), report);
    EXPECT_EQ(report.counts["invalid_samples"], 0u) << path << " pcb";
    EXPECT_GT(report.counts["lvoxels"], 0u) << path << " pcb";
    for (const RGB& p : image.pixels) ASSERT_TRUE(isFinite(p) && p.x >= 0.0f) << path << " pcb";
  }
}

}  // namespace
}  // namespace lvox
