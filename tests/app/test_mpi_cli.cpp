// `mpirun -np 2 lvox ...`: a render split over two ranks gives the one-process image (mc:
// up to the order of float sums; pcb: exactly), one image and one report with each
// rank's times; a sweep renders each point on exactly one rank; a failing or dying rank
// is named and ends the job. Small scenes: each run takes about a second.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/mpi_run.h"
#include "src/core/exr_channels.h"
#include "src/core/image_io.h"
#include "test_util.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

// A box on a floor in a faintly glowing fog bank, lit by a sun and the sky: mc paths
// scatter in the fog and between the surfaces; pcb builds surfels, lvoxels (with the fog's
// emission, exchanged between ranks) and interreflection passes.
const char* kScene = R"({
  "camera": {"position": [0, 1.5, 4], "look_at": [0, 0.3, 0], "vfov_deg": 45, "width": 40, "height": 36},
  "render": {"mode": "mc", "spp": 5, "max_bounces": 4},
  "materials": {"white": {"albedo": 0.7}, "red": {"albedo": [0.7, 0.2, 0.2]}},
  "shapes": [{"type": "quad", "corners": [[-2,0,-2],[2,0,-2],[2,0,2],[-2,0,2]], "material": "white"},
             {"type": "box", "min": [-0.4,0,-0.4], "max": [0.4,0.8,0.4], "material": "red"}],
  "lights": [{"type": "directional", "direction": [0.3, -1, -0.2], "irradiance": 3},
             {"type": "environment", "radiance": 0.2}],
  "media": [{"type": "homogeneous", "min": [-2, 0, -2], "max": [2, 1.2, 2], "sigma_a": 0.1, "sigma_s": 0.3,
              "emission": 0.5}],
  "pointcloud": {"target_surfels": 3000, "lvoxel_spacing": 0.2, "bounces": 3, "gather_spacing": 2}
})";

// The largest |a - b| / |b| over every channel of every pixel (0 where both are 0).
double maxRelativeDifference(const Image& a, const Image& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  double worst = 0.0;
  for (size_t i = 0; i < a.pixels.size() && i < b.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double x = a.pixels[i][c], y = b.pixels[i][c];
      if (x == y) continue;
      worst = std::max(worst, std::abs(x - y) / std::max(std::abs(y), 1e-30));
    }
  return worst;
}

double meanValue(const Image& image) {
  double sum = 0.0;
  for (const RGB& p : image.pixels) sum += p.x + p.y + p.z;
  return sum / (3.0 * static_cast<double>(image.pixels.size()));
}

nlohmann::json readJson(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

class MpiCli : public testing::Test {
 protected:
  void SetUp() override {
    if (!test::haveMpirun())
      GTEST_SKIP() << "lvox was built without MPI (Debian: libopenmpi-dev openmpi-bin; "
                      ".ci/setup installs them)";
    dir_ = test::tempDir();
    test::writeFile(dir_ / "scene.json", kScene);
  }
  std::string scene() const { return (dir_ / "scene.json").string(); }
  std::string path(const char* name) const { return (dir_ / name).string(); }

  // Renders alone and over two ranks with the same flags; returns (alone, ranks).
  std::pair<Image, Image> renderBoth(const std::string& flags) {
    const RunResult alone = runLvox("render " + scene() + " -o " + path("alone.exr") +
                                        " --report " + path("alone.json") + " " + flags,
                                    dir_);
    EXPECT_EQ(alone.exitCode, 0) << alone.err;
    const RunResult ranks = test::runLvoxRanks(2,
                                               "render " + scene() + " -o " + path("ranks.exr") +
                                                   " --report " + path("ranks.json") + " " + flags,
                                               dir_);
    EXPECT_EQ(ranks.exitCode, 0) << ranks.err;
    err_ = ranks.err;
    ImageMetadata meta;
    Image a = readExr(path("alone.exr"));
    Image b = readExr(path("ranks.exr"), &meta);
    meta_ = meta;
    return {std::move(a), std::move(b)};
  }

  void expectTwoRanksReported(const char* phase) {
    const nlohmann::json report = readJson(path("ranks.json"));
    ASSERT_TRUE(report.contains("ranks")) << report.dump();
    ASSERT_EQ(report["ranks"].size(), 2u);
    for (int r = 0; r < 2; ++r) {
      EXPECT_EQ(report["ranks"][r]["rank"].get<int>(), r);
      EXPECT_GT(report["ranks"][r]["times"][phase].get<double>(), 0.0) << report.dump();
    }
    EXPECT_EQ(report["settings"]["ranks"], "2");
    // One summary: only the root writes and prints.
    size_t summaries = 0;
    for (size_t at = err_.find("Mrays/s"); at != std::string::npos;
         at = err_.find("Mrays/s", at + 1))
      ++summaries;
    EXPECT_EQ(summaries, 1u) << err_;
  }

  fs::path dir_;
  std::string err_;
  ImageMetadata meta_;
};

// mc: rank 0 renders samples [2, 4), rank 1 [4, 7) of the chunk [2, 7); each pixel's sum
// is added in another order than one process adds it. All samples are non-negative, so
// the sum's relative rounding error is a few float epsilons (6e-8 each): 1e-5 is two
// orders above it and far below any real difference (a wrong sample range changes
// pixels by tens of percent at 5 spp).
TEST_F(MpiCli, McEqualsOneProcessRender) {
  const auto [alone, ranks] = renderBoth("--mode mc --threads 1 --first-sample 2");
  ASSERT_GT(meanValue(alone), 0.01);
  EXPECT_LT(maxRelativeDifference(ranks, alone), 1e-5);
  EXPECT_EQ(meta_["lvox.spp"], "5");
  EXPECT_EQ(meta_["lvox.first_sample"], "2");
  expectTwoRanksReported("render");
  const nlohmann::json report = readJson(path("ranks.json"));
  EXPECT_EQ(report["counts"]["camera_rays"].get<uint64_t>(), 40u * 36u * 5u);
}

// pcb: the ranks build the cloud between them, split the interreflection's gathers (sums
// with zeros from the other rank are exact) and take bands of tiles: the image is
// identical.
TEST_F(MpiCli, PcbEqualsOneProcessRender) {
  const auto [alone, ranks] = renderBoth("--mode pcb --spp 2 --threads 1");
  ASSERT_GT(meanValue(alone), 0.01);
  EXPECT_EQ(maxRelativeDifference(ranks, alone), 0.0);
  expectTwoRanksReported("interreflection");
  const nlohmann::json report = readJson(path("ranks.json"));
  // 2 samples per pixel and, under the default adaptive samples, 1 more on average.
  EXPECT_EQ(report["counts"]["camera_rays"].get<uint64_t>(), 40u * 36u * 3u);
  EXPECT_GT(report["counts"]["lvoxels"].get<uint64_t>(), 0u);
}

// The rays planned by a preview (surfel_gather_allocation "variance"): the ranks trace the
// preview's rows between them too, so every rank plans the same rays from the same cloud.
TEST_F(MpiCli, PcbWithPlannedSurfelRaysEqualsOneProcessRender) {
  std::string text = kScene;
  const std::string bounces = "\"bounces\": 3,";
  text.replace(text.find(bounces), bounces.size(),
               "\"bounces\": 3, \"surfel_gather_allocation\": \"variance\",");
  test::writeFile(dir_ / "scene.json", text);
  const auto [alone, ranks] = renderBoth("--mode pcb --spp 2 --threads 1");
  ASSERT_GT(meanValue(alone), 0.01);
  EXPECT_EQ(maxRelativeDifference(ranks, alone), 0.0);
  const nlohmann::json report = readJson(path("ranks.json"));
  EXPECT_GT(report["counts"]["cache_preview_rays"].get<uint64_t>(), 0u);
}

// Adaptive samples (render.adaptive_spp): the ranks sum the first samples' moments, plan
// the same extra samples, and split them as the first ones (pcb: by bands of rows, bit for
// bit; mc: by sample ranges, up to the order of the additions).
TEST_F(MpiCli, AdaptiveSamplesEqualOneProcessRender) {
  for (const char* mode : {"pcb", "mc"}) {
    const auto [alone, ranks] =
        renderBoth(std::string("--mode ") + mode + " --spp 2 --adaptive-spp 5 --threads 1");
    ASSERT_GT(meanValue(alone), 0.01) << mode;
    EXPECT_LE(maxRelativeDifference(ranks, alone), std::string(mode) == "mc" ? 1e-5 : 0.0) << mode;
    const nlohmann::json report = readJson(path("ranks.json"));
    const uint64_t pixels = report["counts"]["camera_rays"].get<uint64_t>() / 5u;
    EXPECT_EQ(report["counts"]["adaptive_samples"].get<uint64_t>(), 3u * pixels) << mode;
  }
}

// A forward-scattering fog makes the lvoxels directional (docs/pcb.md): the ranks' shares
// of the interreflection are then nine coefficients per lvoxel row, summed over the ranks
// just as exactly.
TEST_F(MpiCli, PcbWithDirectionalLvoxelsEqualsOneProcessRender) {
  std::string text = kScene;
  const std::string emission = "\"emission\": 0.5}";
  text.replace(text.find(emission), emission.size(), "\"emission\": 0.5, \"g\": 0.7}");
  test::writeFile(dir_ / "scene.json", text);
  const auto [alone, ranks] = renderBoth("--mode pcb --spp 2 --threads 1");
  ASSERT_GT(meanValue(alone), 0.01);
  EXPECT_EQ(maxRelativeDifference(ranks, alone), 0.0);
  const nlohmann::json report = readJson(path("ranks.json"));
  // 9 coefficients per colour per cell in three arrays: 324 bytes a cell at least.
  EXPECT_GT(report["memory"]["lvoxel_light"].get<uint64_t>(),
            324u * report["counts"]["lvoxels"].get<uint64_t>());
}

// The layers are summed over the ranks with the image: each layer of a split render is the
// one-process layer (mc: up to the order of the additions; pcb: bit for bit).
TEST_F(MpiCli, LayersEqualOneProcessRender) {
  for (const char* mode : {"mc", "pcb"}) {
    const std::string layers = std::string(mode) == "mc" ? "all" : "direct,indirect,volume,depth";
    renderBoth(std::string("--mode ") + mode + " --spp 2 --threads 1 --layers " + layers);
    const ExrChannels alone = readExrChannels(path("alone.exr"));
    const ExrChannels ranks = readExrChannels(path("ranks.exr"));
    ASSERT_EQ(alone.names, ranks.names) << mode;
    ASSERT_GT(alone.names.size(), 3u) << mode;
    const float tol = std::string(mode) == "mc" ? 1e-5f : 0.0f;
    for (size_t c = 0; c < alone.names.size(); ++c)
      for (size_t i = 0; i < alone.planes[c].size(); ++i)
        ASSERT_NEAR(ranks.planes[c][i], alone.planes[c][i],
                    tol * (std::abs(alone.planes[c][i]) + 1e-3f))
            << mode << " " << alone.names[c] << " " << i;
  }
}

TEST_F(MpiCli, PcbSurfelsAndDirectEqualOneProcessRender) {
  for (const char* mode : {"pcb-surfels", "direct"}) {
    const auto [alone, ranks] = renderBoth(std::string("--mode ") + mode + " --threads 1");
    EXPECT_EQ(maxRelativeDifference(ranks, alone), 0.0) << mode;
  }
}

// The point cloud is built once across the ranks, not on each: every rank samples the
// surfels of its slice of the triangles, probes its range of them for burial, samples its
// slices of lvoxel cells and lights its blocks of them, and the pieces are exchanged. Each rank's
// share of that work is in the report ("work"): the shares add up to the one-process work and none
// is all of it, and the image is identical (0 difference) in pcb (surfels and lvoxels) and
// pcb-surfels. The second round sends everything in 4 KiB pieces: the chunked path that
// transfers past 2 GiB take.
TEST_F(MpiCli, PointCloudBuiltOnceAcrossRanks) {
  for (const char* piece : {"", "4096"}) {
    if (*piece) setenv("LVOX_MPI_PIECE_BYTES", piece, 1);
    for (const char* mode : {"pcb", "pcb-surfels"}) {
      SCOPED_TRACE(std::string(mode) + (*piece ? " in 4 KiB pieces" : ""));
      const auto [alone, ranks] =
          renderBoth(std::string("--mode ") + mode + " --spp 2 --threads 1");
      ASSERT_GT(meanValue(alone), 0.01);
      EXPECT_EQ(maxRelativeDifference(ranks, alone), 0.0);
      nlohmann::json one = readJson(path("alone.json"));
      nlohmann::json two = readJson(path("ranks.json"));
      std::vector<std::string> split = {"surfel_triangles", "surfels_sampled", "surfels_probed"};
      if (std::string(mode) == "pcb")
        split.insert(split.end(), {"lvoxels_sampled", "lvoxel_direct_cells"});
      ASSERT_EQ(two["ranks"].size(), 2u) << two.dump();
      for (const std::string& key : split) {
        const uint64_t whole = one.at("work").at(key).get<uint64_t>();
        ASSERT_GT(whole, 0u) << key;
        uint64_t sum = 0;
        for (const nlohmann::json& rank : two["ranks"]) {
          const uint64_t share = rank.at("work").at(key).get<uint64_t>();
          EXPECT_GT(share, 0u) << key << ": a rank did none of it";
          EXPECT_LT(share, whole) << key << ": a rank did all of it";
          sum += share;
        }
        EXPECT_EQ(sum, whole) << key;
      }
      // The same cloud: the one-process counts, and the exchange measured on both ranks.
      for (const char* count : {"surfels", "buried_surfels", "lvoxels", "octree_nodes"})
        EXPECT_EQ(two["counts"][count], one["counts"][count]) << count;
      EXPECT_EQ(one["counts"]["triangles"], two["counts"]["triangles"]);
      for (const nlohmann::json& rank : two["ranks"])
        EXPECT_GT(rank.at("times").at("cloud_exchange").get<double>(), 0.0) << two.dump();
    }
  }
  unsetenv("LVOX_MPI_PIECE_BYTES");
}

// Three ranks: uneven shares (lvoxel slices k mod 3, three triangle ranges, merges of three
// pieces) still give the one-process cloud and image, and the shares add up.
TEST_F(MpiCli, PointCloudOverThreeRanksEqualsOneProcessRender) {
  const std::string flags = " --mode pcb --spp 2 --threads 1";
  const RunResult alone = runLvox(
      "render " + scene() + " -o " + path("alone.exr") + " --report " + path("alone.json") + flags,
      dir_);
  ASSERT_EQ(alone.exitCode, 0) << alone.err;
  const RunResult three = test::runLvoxRanks(
      3,
      "render " + scene() + " -o " + path("three.exr") + " --report " + path("three.json") + flags,
      dir_);
  ASSERT_EQ(three.exitCode, 0) << three.err;
  EXPECT_EQ(maxRelativeDifference(readExr(path("three.exr")), readExr(path("alone.exr"))), 0.0);
  nlohmann::json one = readJson(path("alone.json"));
  nlohmann::json all = readJson(path("three.json"));
  ASSERT_EQ(all["ranks"].size(), 3u);
  for (const auto& [key, whole] : one.at("work").items()) {
    uint64_t sum = 0;
    for (const nlohmann::json& rank : all["ranks"]) sum += rank.at("work").at(key).get<uint64_t>();
    EXPECT_EQ(sum, whole.get<uint64_t>()) << key;
  }
  for (const char* count : {"surfels", "buried_surfels", "lvoxels", "octree_nodes"})
    EXPECT_EQ(all["counts"][count], one["counts"][count]) << count;
}

// Each point is rendered by exactly one rank, and the CSV equals the one-process sweep's
// in everything but the times.
TEST_F(MpiCli, SweepSplitsItsPointsOverRanks) {
  fs::create_directories(dir_ / "alone");
  fs::create_directories(dir_ / "ranks");
  const std::string flags =
      " --mode direct --methods rk4,euler --step-scales 2,1 --width 16 --height 12 --threads 1 "
      "--no-plot";
  const RunResult alone = runLvox("sweep " + scene() + " -o " + path("alone") + flags, dir_);
  ASSERT_EQ(alone.exitCode, 0) << alone.err;
  const RunResult ranks =
      test::runLvoxRanks(2, "sweep " + scene() + " -o " + path("ranks") + flags, dir_);
  ASSERT_EQ(ranks.exitCode, 0) << ranks.err;
  EXPECT_NE(ranks.err.find("over 2 ranks"), std::string::npos) << ranks.err;
  size_t rendered = 0;
  for (size_t at = ranks.err.find("(rank "); at != std::string::npos;
       at = ranks.err.find("(rank ", at + 1))
    ++rendered;
  EXPECT_EQ(rendered, 4u) << ranks.err;
  auto columns = [](const fs::path& csv) {
    std::ifstream in(csv);
    std::vector<std::string> kept;
    for (std::string line; std::getline(in, line);) {
      std::vector<std::string> cells;
      std::stringstream ss(line);
      for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
      // Everything but the seconds (column 5) and the time Pareto flag (16).
      std::string row;
      for (size_t c = 0; c < cells.size(); ++c)
        if (c != 5 && c != 16) row += cells[c] + ",";
      kept.push_back(row);
    }
    return kept;
  };
  const auto a = columns(dir_ / "alone" / "sweep.csv"), b = columns(dir_ / "ranks" / "sweep.csv");
  ASSERT_EQ(a.size(), 5u);
  EXPECT_EQ(a, b);
  // Each rank kept the images of its points.
  ASSERT_TRUE(fs::exists(dir_ / "ranks" / "points"));
  EXPECT_EQ(
      std::distance(fs::directory_iterator(dir_ / "ranks" / "points"), fs::directory_iterator{}),
      4);
}

// An error on a rank names the rank and ends the whole job; nothing is written.
TEST_F(MpiCli, RankErrorIsNamedAndEndsTheJob) {
  const RunResult r = test::runLvoxRanks(
      2, "render " + scene() + " -o " + path("out.exr") + " --time-limit 5", dir_);
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find(" of 2 on "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--time-limit: is not available in a render split over MPI ranks"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.exr"));
}

// The work budget over ranks: each rank projects its own share and the first past the
// budget ends the job with the budget's message; nothing is written. (A fine fixed step
// through the fog asks for about 1e8 evaluations.)
TEST_F(MpiCli, WorkBudgetEndsTheJobOnEveryRank) {
  const RunResult r = test::runLvoxRanks(2,
                                         "render " + scene() + " -o " + path("out.exr") +
                                             " --mode direct --solver rk4 --step 0.001"
                                             " --max-evaluations 1e6",
                                         dir_);
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("render.max_evaluations: the camera rays would need about "),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.exr"));
}

// Rank 1 is killed in the middle of a long render while rank 0 waits for it: the launcher
// names the rank that died, ends the job instead of hanging, and no image is written.
TEST_F(MpiCli, KilledRankIsNamedAndEndsTheJob) {
  const std::string render = std::string(LVOX_BINARY) + " render " + scene() + " -o " +
                             path("out.exr") + " --mode mc --spp 100000 --threads 1";
  const std::string wrapper =
      "sh -c 'if [ \"$OMPI_COMM_WORLD_RANK\" = 1 ]; then exec timeout -s "
      "KILL 1 " +
      render + "; else exec " + render + "; fi'";
  const fs::path errFile = dir_ / "stderr.txt";
  const int status =
      std::system((test::mpirunPrefix(2) + wrapper + " >/dev/null 2>" + errFile.string()).c_str());
  std::ifstream in(errFile);
  std::ostringstream err;
  err << in.rdbuf();
  EXPECT_NE(status, 0);
  EXPECT_NE(err.str().find("rank 1"), std::string::npos) << err.str();
  EXPECT_FALSE(fs::exists(dir_ / "out.exr"));
}

}  // namespace
}  // namespace lvox
