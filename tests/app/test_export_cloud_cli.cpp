// `lvox render --export-cloud`: the cloud lands beside the image, published with it, as
// many points as the report counts elements; a mode without a cloud, another extension or
// a path taken by another output is one line and nothing written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/run_lvox.h"
#include "test_util.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

const char* kScene = R"({
  "camera": {"position": [0, 1.5, 4], "look_at": [0, 0.3, 0], "vfov_deg": 45, "width": 16, "height": 12},
  "render": {"spp": 1},
  "materials": {"white": {"albedo": 0.7}},
  "shapes": [{"type": "quad", "corners": [[-2,0,-2],[2,0,-2],[2,0,2],[-2,0,2]], "material": "white"}],
  "lights": [{"type": "directional", "direction": [0.3, -1, -0.2], "irradiance": 3}],
  "media": [{"type": "homogeneous", "min": [-1, 0, -1], "max": [1, 1, 1], "sigma_s": 0.3}],
  "pointcloud": {"target_surfels": 2000, "lvoxel_spacing": 0.25}
})";

TEST(ExportCloudCli, PlyHoldsEveryElementTheReportCounts) {
  const fs::path dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  const RunResult r =
      runLvox("render " + (dir / "scene.json").string() + " -o " + (dir / "out.exr").string() +
                  " --report " + (dir / "r.json").string() + " --export-cloud " +
                  (dir / "cloud.ply").string(),
              dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::ifstream report(dir / "r.json");
  const nlohmann::json j = nlohmann::json::parse(report);
  const uint64_t elements =
      j["counts"]["surfels"].get<uint64_t>() + j["counts"]["lvoxels"].get<uint64_t>();
  ASSERT_GT(j["counts"]["lvoxels"].get<uint64_t>(), 0u);
  std::ifstream ply(dir / "cloud.ply", std::ios::binary);
  std::string line;
  uint64_t declared = 0;
  while (std::getline(ply, line) && line != "end_header")
    if (line.rfind("element vertex ", 0) == 0) declared = std::stoull(line.substr(15));
  EXPECT_EQ(declared, elements);
  const auto bodyStart = ply.tellg();
  ply.seekg(0, std::ios::end);
  EXPECT_EQ(static_cast<uint64_t>(ply.tellg() - bodyStart), elements * 60u);  // 14 floats + 4
}

TEST(ExportCloudCli, RefusedWithoutACloudOrWithAnotherExtensionOrPath) {
  const fs::path dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  const std::string base =
      "render " + (dir / "scene.json").string() + " -o " + (dir / "out.exr").string();
  struct Case {
    std::string flags, expect;
  };
  for (const Case& c :
       {Case{"--mode direct --export-cloud " + (dir / "c.ply").string(), "needs mode pcb"},
        Case{"--export-cloud " + (dir / "c.txt").string(), "must end in .ply or .vdb"},
        Case{"--export-cloud " + (dir / "scene.json").string(), "--export-cloud"},
        Case{"--report " + (dir / "r.vdb").string() + " --export-cloud " + (dir / "r.vdb").string(),
             "same file as another output"}}) {
    const RunResult r = runLvox(base + " " + c.flags, dir);
    EXPECT_NE(r.exitCode, 0) << c.flags;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.flags << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.exr")) << c.flags;
    EXPECT_FALSE(fs::exists(dir / "c.ply")) << c.flags;
  }
  EXPECT_TRUE(fs::exists(dir / "scene.json"));
}

}  // namespace
}  // namespace lvox
