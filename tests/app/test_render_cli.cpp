// End-to-end: the lvox executable, its outputs and its handling of bad input.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/run_lvox.h"
#include "src/core/image_io.h"
#include "src/core/image_metrics.h"
#include "test_util.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

const char* kScene = R"({
  "camera": {"position": [0, 2, 4], "look_at": [0, 0, 0], "vfov_deg": 40, "width": 48, "height": 32},
  "render": {"mode": "direct", "spp": 2},
  "materials": {"white": {"albedo": 0.7}},
  "shapes": [{"type": "quad", "corners": [[-2,0,-2],[2,0,-2],[2,0,2],[-2,0,2]], "material": "white"},
             {"type": "box", "min": [-0.3,0,-0.3], "max": [0.3,0.6,0.3], "material": "white"}],
  "lights": [{"type": "directional", "direction": [0.3, -1, -0.2], "irradiance": 3},
             {"type": "environment", "radiance": 0.1}]
})";

std::vector<std::string> listDir(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(RenderCli, WritesExrPngAndReport) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  const RunResult r =
      runLvox("render " + (dir / "scene.json").string() + " -o " + (dir / "out.exr").string() +
                  " --report " + (dir / "report.json").string(),
              dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(listDir(dir),
            (std::vector<std::string>{"out.exr", "out.png", "report.json", "scene.json"}));
  std::ifstream in(dir / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_GT(report["times"]["total"].get<double>(), 0.0);
  EXPECT_EQ(report["counts"]["camera_rays"].get<uint64_t>(), 48u * 32u * 2u);
  EXPECT_GT(report["memory"]["peak_rss"].get<uint64_t>(), 0u);
  EXPECT_NE(r.err.find("48x32"), std::string::npos) << "summary line: " << r.err;
}

// Each bad input: non-zero exit, one line on stderr naming the file and the field, and
// nothing written.
void expectCleanFailure(const std::string& sceneText, const std::string& field,
                        const std::string& file = "scene.json", const std::string& flags = "") {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", sceneText);
  const RunResult r = runLvox(
      "render " + (dir / "scene.json").string() + " -o " + (dir / "out.exr").string() + flags, dir);
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(field), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(listDir(dir), std::vector<std::string>{"scene.json"});
}

std::string replaced(const std::string& from, const std::string& to) {
  std::string s = kScene;
  return s.replace(s.find(from), from.size(), to);
}

TEST(RenderCli, MalformedJson) {
  expectCleanFailure(replaced("\"spp\": 2}", "\"spp\": 2"), "line");
}
TEST(RenderCli, WrongType) {
  expectCleanFailure(replaced("\"width\": 48", "\"width\": \"48\""), "camera.width");
}
TEST(RenderCli, NaNValue) {
  expectCleanFailure(replaced("\"irradiance\": 3", "\"irradiance\": NaN"), "malformed JSON");
}
TEST(RenderCli, NegativeResolution) {
  expectCleanFailure(replaced("\"height\": 32", "\"height\": -32"), "camera.height");
}
TEST(RenderCli, UnknownKey) {
  expectCleanFailure(replaced("\"spp\": 2", "\"sps\": 2"), "render.sps");
}
TEST(RenderCli, LvoxelSpacingFarTooSmall) {
  expectCleanFailure(
      replaced(
          "\"mode\": \"direct\", \"spp\": 2}",
          "\"mode\": \"pcb\", \"spp\": 2}, \"pointcloud\": {\"lvoxel_spacing\": 1e-6},\n"
          "  \"media\": [{\"type\": \"homogeneous\", \"min\": [-1, -1, -1], \"max\": [1, 1, 1], "
          "\"sigma_s\": 1}]"),
      "pointcloud.lvoxel_spacing");
}
// 1e-6 used to loop, 1e-3 to grow past 7 GB, 1e-4 to end in std::bad_alloc naming nothing.
std::string pcbScene(const std::string& pointcloud) {
  return replaced("\"mode\": \"direct\", \"spp\": 2}",
                  "\"mode\": \"pcb\", \"spp\": 2}, \"pointcloud\": " + pointcloud);
}

// 1e-6 asks for 2e13 surfels, past what the octree can index; 1e-3 for 2e7 surfels,
// about 7 GB, past a budget of 2 GB. Both are refused before any surfel is sampled.
TEST(RenderCli, SurfelSpacingFarTooSmall) {
  expectCleanFailure(pcbScene("{\"surfel_spacing\": 1e-6}"), "pointcloud.surfel_spacing");
  expectCleanFailure(pcbScene("{\"surfel_spacing\": 1e-3}"),
                     "pointcloud.surfel_spacing: the point cloud (about 2", "scene.json",
                     " --max-memory 2G");
}

// The memory budget: from the flag or the scene file, checked before the point cloud is
// sampled, the message naming the setting, the budget and how to raise it.
TEST(RenderCli, MemoryBudgetStopsARenderBeforeItAllocates) {
  const std::string many = pcbScene("{\"target_surfels\": 2000000}");
  expectCleanFailure(many, "past the memory budget of 256.0 MB", "scene.json",
                     " --max-memory 256M");
  expectCleanFailure(many, "pointcloud.target_surfels", "scene.json", " --max-memory 256M");
  expectCleanFailure(many, "raise it with --max-memory", "scene.json", " --max-memory 256M");
  std::string inFile = many;
  const std::string spp = "\"spp\": 2";
  inFile.replace(inFile.find(spp), spp.size(), spp + ", \"max_memory\": \"256M\"");
  expectCleanFailure(inFile, "past the memory budget of 256.0 MB");
  // The default scene's cloud fits in the same budget and renders.
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", pcbScene("{\"target_surfels\": 20000}"));
  const RunResult r =
      runLvox("render " + (dir / "scene.json").string() + " -o " + (dir / "out.exr").string() +
                  " --max-memory 256M" + " --report " + (dir / "r.json").string(),
              dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::ifstream in(dir / "r.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["memory"]["budget"].get<uint64_t>(), 256u << 20);
  EXPECT_GT(report["memory"]["budget_reserved"].get<uint64_t>(), 20000u * 250u);
  EXPECT_LT(report["memory"]["budget_reserved"].get<uint64_t>(), 256u << 20);
}

// The work budget: a fine fixed step through fog asks for about 1.7e6 medium evaluations;
// with a budget of 1e6 the camera phase is projected past it after a few percent of its
// samples and the render stops with one line and no output. The same scene renders within
// the default budget, which the report states.
TEST(RenderCli, WorkBudgetStopsARenderProjectedPastIt) {
  std::string fog =
      replaced("\"lights\": [",
               "\"media\": [{\"type\": \"homogeneous\", \"min\": [-1, 0, -1], \"max\": [1, 1, 1], "
               "\"sigma_s\": 0.5}], \"volume_integrator\": {\"solver\": \"rk4\", \"step\": 0.001}, "
               "\"lights\": [");
  expectCleanFailure(fog, "render.max_evaluations: the camera rays would need about ", "scene.json",
                     " --max-evaluations 1e6");
  expectCleanFailure(fog, "past the budget of 1e+06; raise it with --max-evaluations", "scene.json",
                     " --max-evaluations 1e6");
  std::string inFile = fog;
  const std::string spp = "\"spp\": 2";
  inFile.replace(inFile.find(spp), spp.size(), spp + ", \"max_evaluations\": \"1e6\"");
  expectCleanFailure(inFile, "(projected after ");
  std::string asNumber = fog;  // a JSON number works as well as a string
  asNumber.replace(asNumber.find(spp), spp.size(), spp + ", \"max_evaluations\": 1e6");
  expectCleanFailure(asNumber, "past the budget of 1e+06");
  std::string tooSmall = fog;
  tooSmall.replace(tooSmall.find(spp), spp.size(), spp + ", \"max_evaluations\": 10");
  expectCleanFailure(tooSmall, "render.max_evaluations");
  expectCleanFailure(fog, "--max-evaluations: \"lots\"", "", " --max-evaluations lots");
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", fog);
  const RunResult r =
      runLvox("render " + (dir / "scene.json").string() + " -o " + (dir / "out.exr").string() +
                  " --report " + (dir / "r.json").string(),
              dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::ifstream in(dir / "r.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["counts"]["evaluation_budget"].get<uint64_t>(), 10000000000u);
  EXPECT_GT(report["counts"]["medium_evals"].get<uint64_t>(), 1500000u);
}

TEST(RenderCli, MissingMesh) {
  expectCleanFailure(
      replaced("\"shapes\": [", "\"shapes\": [{\"type\": \"obj\", \"file\": \"nope.obj\"},"),
      "shapes[0].file", "nope.obj");
}

// A bad flag value is refused with one line naming the flag, before the (missing) mesh is
// read and before anything is written.
TEST(RenderCli, BadFlagValuesNameTheFlagBeforeAnyAssetIsLoaded) {
  const auto dir = test::tempDir();
  test::writeFile(
      dir / "scene.json",
      replaced("\"shapes\": [", "\"shapes\": [{\"type\": \"obj\", \"file\": \"nope.obj\"},"));
  for (const auto& [flags, expected] :
       {std::pair<std::string, std::string>{"--solver rk5",
                                            "lvox: error: --solver: unknown solver 'rk5'"},
        {"--mode nope", "lvox: error: --mode: unknown mode 'nope'"},
        {"--step 1e-9", "lvox: error: --step: value 1e-09 is outside"},
        {"--seed -1", "lvox: error: --seed: value -1 is outside"},
        {"--max-memory 4Q", "lvox: error: --max-memory: \"4Q\": unknown unit"},
        {"--max-memory 0.5M", "lvox: error: --max-memory: \"0.5M\": must be at least 1M"}}) {
    const RunResult r = runLvox("render " + (dir / "scene.json").string() + " " + flags + " -o " +
                                    (dir / "out.exr").string(),
                                dir);
    EXPECT_EQ(r.exitCode, 1) << flags;
    EXPECT_EQ(r.err.rfind(expected, 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(listDir(dir), std::vector<std::string>{"scene.json"});
  }
}

// Usage errors are one line with the prefix, like input errors; a NaN time budget is an
// error, not an endless render.
TEST(RenderCli, UsageErrorsAreOneLine) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  for (const std::string& args :
       {"render " + (dir / "scene.json").string() + " --spp abc -o " + (dir / "a.exr").string(),
        std::string("bogus"),
        "render " + (dir / "scene.json").string() + " --time-limit nan -o " +
            (dir / "a.exr").string()}) {
    const RunResult r = runLvox(args, dir);
    EXPECT_NE(r.exitCode, 0) << args;
    EXPECT_EQ(r.err.rfind("lvox: error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  EXPECT_EQ(listDir(dir), std::vector<std::string>{"scene.json"});
}

TEST(RenderCli, MissingSceneFile) {
  const auto dir = test::tempDir();
  const RunResult r = runLvox(
      "render " + (dir / "absent.json").string() + " -o " + (dir / "out.exr").string(), dir);
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("absent.json"), std::string::npos) << r.err;
  EXPECT_TRUE(listDir(dir).empty());
}

TEST(RenderCli, RefusesToOverwriteInputAndMissingDirectory) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  RunResult r = runLvox(
      "render " + (dir / "scene.json").string() + " -o " + (dir / "nodir" / "out.exr").string(),
      dir);
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("nodir"), std::string::npos) << r.err;
  // An output named like the scene (scene.json as the report) must not destroy it.
  r = runLvox("render " + (dir / "scene.json").string() + " -o " + (dir / "out.exr").string() +
                  " --report " + (dir / "scene.json").string(),
              dir);
  EXPECT_NE(r.exitCode, 0);
  std::ifstream in(dir / "scene.json");
  std::ostringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), kScene);
  EXPECT_EQ(listDir(dir), std::vector<std::string>{"scene.json"});
}

// Every command checks each output against every file it reads (the OBJ's MTL library,
// a convergence reference, compare's images, merge's chunks) before writing anything.
TEST(RenderCli, NoOutputReplacesAnyFileTheCommandReads) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "mesh.obj",
                  "mtllib mesh.mtl\nv 0 0 0\nv 1 0 0\nv 0 0 1\nusemtl m\nf 1 2 3\n");
  const std::string mtl = "newmtl m\nKd 0.5 0.5 0.5\n";
  test::writeFile(dir / "mesh.mtl", mtl);
  test::writeFile(
      dir / "scene.json",
      replaced("\"shapes\": [", "\"shapes\": [{\"type\": \"obj\", \"file\": \"mesh.obj\"},"));
  const std::string scene = (dir / "scene.json").string();
  ASSERT_EQ(runLvox("render " + scene + " -o " + (dir / "a.exr").string(), dir).exitCode, 0);
  auto contents = [&](const std::string& name) {
    std::ifstream in(dir / name, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  };
  const std::string exr = contents("a.exr");
  const std::pair<std::string, std::string> cases[] = {
      {"render " + scene + " -o " + (dir / "b.exr").string() + " --report " +
           (dir / "mesh.mtl").string(),
       "--report: would overwrite the input"},
      {"render " + scene + " -o " + (dir / "a.exr").string() + " --convergence " +
           (dir / "a.exr").string() + " --convergence-csv " + (dir / "c.csv").string(),
       "--output: would overwrite the input"},
      {"compare " + (dir / "a.exr").string() + " " + (dir / "a.exr").string() + " --heatmap " +
           (dir / "a.exr").string(),
       "--heatmap: must end in .png"},
      {"merge " + (dir / "a.exr").string() + " -o " + (dir / "a.exr").string(),
       "--output: would overwrite the input"}};
  for (const auto& [args, expected] : cases) {
    const RunResult r = runLvox(args, dir);
    EXPECT_EQ(r.exitCode, 1) << args;
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  }
  EXPECT_EQ(contents("mesh.mtl"), mtl);
  EXPECT_EQ(contents("a.exr"), exr);
  EXPECT_EQ(listDir(dir),
            (std::vector<std::string>{"a.exr", "a.png", "mesh.mtl", "mesh.obj", "scene.json"}));
}

TEST(RenderCli, SameImageForAnyThreadCount) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  ASSERT_EQ(runLvox("render " + (dir / "scene.json").string() + " -o " + (dir / "a.exr").string() +
                        " --threads 1",
                    dir)
                .exitCode,
            0);
  ASSERT_EQ(runLvox("render " + (dir / "scene.json").string() + " -o " + (dir / "b.exr").string() +
                        " --threads 2",
                    dir)
                .exitCode,
            0);
  std::ifstream a(dir / "a.exr", std::ios::binary), b(dir / "b.exr", std::ios::binary);
  std::ostringstream sa, sb;
  sa << a.rdbuf();
  sb << b.rdbuf();
  EXPECT_EQ(sa.str(), sb.str());
}

}  // namespace
}  // namespace lvox

namespace lvox {
namespace {

TEST(RenderCli, ChunksMergeIntoTheFullRender) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  const std::string scene = (dir / "scene.json").string() + " --mode mc --spp 3";
  ASSERT_EQ(runLvox("render " + scene + " -o " + (dir / "a.exr").string(), dir).exitCode, 0);
  ASSERT_EQ(
      runLvox("render " + scene + " --first-sample 3 -o " + (dir / "b.exr").string(), dir).exitCode,
      0);
  ASSERT_EQ(runLvox("render " + (dir / "scene.json").string() + " --mode mc --spp 6 -o " +
                        (dir / "full.exr").string(),
                    dir)
                .exitCode,
            0);
  ASSERT_EQ(runLvox("merge " + (dir / "a.exr").string() + " " + (dir / "b.exr").string() + " -o " +
                        (dir / "merged.exr").string(),
                    dir)
                .exitCode,
            0);
  const Image merged = readExr((dir / "merged.exr").string());
  const Image full = readExr((dir / "full.exr").string());
  // Same samples, different summation order: equal to float rounding.
  EXPECT_LT(compareImages(merged, full).maxAbs, 1e-5);
  // Merging a chunk with itself would double-count samples: refused.
  const RunResult r = runLvox("merge " + (dir / "a.exr").string() + " " + (dir / "a.exr").string() +
                                  " -o " + (dir / "bad.exr").string(),
                              dir);
  EXPECT_NE(r.exitCode, 0);
  EXPECT_FALSE(fs::exists(dir / "bad.exr"));
}

// A chunk rendered with another setting, or from an edited scene, is not part of the same
// image: merge names what differs and writes nothing.
TEST(RenderCli, MergeRefusesChunksWhoseSettingsOrSceneDiffer) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  const std::string scene = (dir / "scene.json").string() + " --mode mc --spp 2";
  ASSERT_EQ(runLvox("render " + scene + " -o " + (dir / "a.exr").string(), dir).exitCode, 0);
  ASSERT_EQ(runLvox("render " + scene + " --first-sample 2 --max-bounces 1 -o " +
                        (dir / "bounces.exr").string(),
                    dir)
                .exitCode,
            0);
  ASSERT_EQ(
      runLvox("render " + scene + " --first-sample 2 --step 0.05 -o " + (dir / "step.exr").string(),
              dir)
          .exitCode,
      0);
  test::writeFile(dir / "scene.json", replaced("\"irradiance\": 3", "\"irradiance\": 4"));
  ASSERT_EQ(
      runLvox("render " + scene + " --first-sample 2 -o " + (dir / "edited.exr").string(), dir)
          .exitCode,
      0);
  for (const auto& [chunk, key] :
       {std::pair<std::string, std::string>{"bounces.exr", "lvox.render.max_bounces"},
        {"step.exr", "lvox.volume_integrator.step"},
        {"edited.exr", "lvox.scene_hash"}}) {
    const RunResult r = runLvox("merge " + (dir / "a.exr").string() + " " + (dir / chunk).string() +
                                    " -o " + (dir / "merged.exr").string(),
                                dir);
    EXPECT_EQ(r.exitCode, 1) << chunk;
    EXPECT_NE(r.err.find(chunk + ": " + key + ": differs"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "merged.exr"));
  }
}

// The point cloud's settings change only pcb images. An MC chunk does not record them, and
// MC chunks from before that (which carry them) merge with new ones even where a cloud
// default has changed since; pcb chunks still must agree on them.
TEST(RenderCli, MergeComparesTheCloudsSettingsOnlyInThePcbModes) {
  const auto dir = test::tempDir();
  // Without adaptive samples, so that pcb chunks from --first-sample 2 are chunks of one image.
  test::writeFile(dir / "scene.json", replaced("\"spp\": 2}", "\"spp\": 2, \"adaptive_spp\": 0}"));
  for (const std::string mode : {"mc", "pcb"})
    for (const std::string first : {"0", "2"})
      ASSERT_EQ(runLvox("render " + (dir / "scene.json").string() + " --mode " + mode +
                            " --spp 2 --first-sample " + first + " -o " +
                            (dir / (mode + first + ".exr")).string(),
                        dir)
                    .exitCode,
                0);
  const auto cloudKeys = [](const ImageMetadata& meta) {
    return std::count_if(meta.begin(), meta.end(),
                         [](const auto& kv) { return kv.first.rfind("lvox.pointcloud.", 0) == 0; });
  };
  // A chunk as an older lvox wrote it: the MC image with a cloud setting another default
  // would give (the pcb chunk's keys, one of them changed).
  ImageMetadata mc, pcb;
  const Image mcImage = readExr((dir / "mc2.exr").string(), &mc);
  readExr((dir / "pcb2.exr").string(), &pcb);
  EXPECT_EQ(cloudKeys(mc), 0);
  ASSERT_GT(cloudKeys(pcb), 5);
  for (ImageMetadata* meta : {&mc, &pcb}) {
    for (const auto& [key, value] : pcb)
      if (key.rfind("lvox.pointcloud.", 0) == 0) (*meta)[key] = value;
    (*meta)["lvox.pointcloud.surfel_gather_samples"] = "17";
  }
  writeExr((dir / "mc_old.exr").string(), mcImage, false, mc);
  const Image pcbImage = readExr((dir / "pcb2.exr").string());
  writeExr((dir / "pcb_old.exr").string(), pcbImage, false, pcb);

  const auto merge = [&](const std::string& a, const std::string& b) {
    return runLvox("merge " + (dir / a).string() + " " + (dir / b).string() + " -o " +
                       (dir / "merged.exr").string(),
                   dir);
  };
  EXPECT_EQ(merge("mc0.exr", "mc_old.exr").exitCode, 0);
  ImageMetadata merged;
  readExr((dir / "merged.exr").string(), &merged);
  EXPECT_EQ(merged.at("lvox.spp"), "4");
  fs::remove(dir / "merged.exr");
  const RunResult r = merge("pcb0.exr", "pcb_old.exr");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("lvox.pointcloud.surfel_gather_samples: differs"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "merged.exr"));
}

// pcb's adaptive samples ("auto") need the whole image's first samples: a chunk from
// --first-sample 0 takes them and a later chunk cannot (it warns). Their samples would
// overlap, so merge refuses the pair, naming the setting.
TEST(RenderCli, MergeRefusesAChunkWithAdaptiveSamplesBesideOneWithout) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  const std::string scene = (dir / "scene.json").string() + " --mode pcb --spp 2";
  ASSERT_EQ(runLvox("render " + scene + " -o " + (dir / "a.exr").string(), dir).exitCode, 0);
  const RunResult later =
      runLvox("render " + scene + " --first-sample 2 -o " + (dir / "b.exr").string(), dir);
  ASSERT_EQ(later.exitCode, 0);
  EXPECT_NE(later.err.find("adaptive samples are off"), std::string::npos) << later.err;
  const RunResult r = runLvox("merge " + (dir / "a.exr").string() + " " + (dir / "b.exr").string() +
                                  " -o " + (dir / "merged.exr").string(),
                              dir);
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("lvox.render.adaptive_spp: differs"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "merged.exr"));
}

// --exposure scales the PNG preview by 2^E before its tone map, and never the EXR.
TEST(RenderCli, ExposureScalesThePreviewNotTheExr) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  const std::string scene = (dir / "scene.json").string();
  ASSERT_EQ(runLvox("render " + scene + " -o " + (dir / "a.exr").string(), dir).exitCode, 0);
  ASSERT_EQ(
      runLvox("render " + scene + " --exposure 1.5 -o " + (dir / "b.exr").string(), dir).exitCode,
      0);
  const Image a = readExr((dir / "a.exr").string());
  EXPECT_EQ(a.pixels, readExr((dir / "b.exr").string()).pixels);
  const Image png = readAnyImage((dir / "b.exr").replace_extension(".png").string());
  const float scale = std::exp2(1.5f);
  int checked = 0;
  for (size_t i = 0; i < a.pixels.size(); i += 37)
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(png.pixels[i][c] * 255.0f, toneMap(a.pixels[i][c], scale), 0.51f) << i;
      ++checked;
    }
  EXPECT_GT(checked, 100);
  const RunResult bad =
      runLvox("render " + scene + " --exposure 40 -o " + (dir / "c.exr").string(), dir);
  EXPECT_NE(bad.exitCode, 0);
  EXPECT_NE(bad.err.find("--exposure"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "c.exr"));
}

TEST(RenderCli, VersionNamesTheRevision) {
  const auto dir = test::tempDir();
  const std::string out = (dir / "version.txt").string();
  ASSERT_EQ(std::system((std::string(LVOX_BINARY) + " --version > " + out).c_str()), 0);
  std::ifstream in(out);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("lvox 0.1.0 (git ", 0), 0u) << line;
}

TEST(RenderCli, ConvergenceCsvHasOneRowPerDoubling) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  const std::string scene = (dir / "scene.json").string() + " --mode mc";
  ASSERT_EQ(runLvox("render " + scene + " --spp 64 -o " + (dir / "ref.exr").string(), dir).exitCode,
            0);
  ASSERT_EQ(runLvox("render " + scene + " --seed 9 --spp 8 -o " + (dir / "t.exr").string() +
                        " --convergence " + (dir / "ref.exr").string() + " --convergence-csv " +
                        (dir / "conv.csv").string(),
                    dir)
                .exitCode,
            0);
  std::ifstream in(dir / "conv.csv");
  std::string line;
  std::vector<std::string> rows;
  while (std::getline(in, line)) rows.push_back(line);
  ASSERT_EQ(rows.size(), 5u);  // header + 1, 2, 4, 8 spp
  EXPECT_EQ(rows[1].substr(0, 2), "1,");
  EXPECT_EQ(rows[4].substr(0, 2), "8,");
}

}  // namespace
}  // namespace lvox

namespace lvox {
namespace {

// The shipped scenes load and render (small and fast here; full size in the README).
void expectSceneRenders(const std::string& scenePath, const std::string& mode) {
  const auto dir = test::tempDir();
  const RunResult r =
      runLvox("render " + scenePath + " --mode " + mode + " --spp 1 -o " +
                  (dir / "out.exr").string() + " --report " + (dir / "r.json").string(),
              dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Image image = readExr((dir / "out.exr").string());
  double sum = 0.0;
  for (const RGB& p : image.pixels) sum += p.x + p.y + p.z;
  EXPECT_GT(sum / static_cast<double>(image.pixels.size()), 0.01) << "image is black";
}

TEST(Scenes, AtriumRendersInDirectMcAndPcbModes) {
  const std::string atrium = std::string(LVOX_SOURCE_DIR) + "/scenes/atrium.json";
  expectSceneRenders(atrium, "direct");
  expectSceneRenders(atrium, "mc");
  expectSceneRenders(atrium, "pcb");
}

// The README's first command: the atrium with the smoke plume in pcb mode (smaller here).
TEST(Scenes, AtriumWithSmokeRendersInPcbMode) {
  const auto dir = test::tempDir();
  const std::string scene = std::string(LVOX_SOURCE_DIR) + "/scenes/atrium_smoke.json";
  const RunResult r =
      runLvox("render " + scene + " --width 96 --height 96 --spp 1 -o " +
                  (dir / "out.exr").string() + " --report " + (dir / "r.json").string(),
              dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  // The readable profile on stderr.
  EXPECT_NE(r.err.find("lvox: phases: surfel_sampling"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" lvoxels, "), std::string::npos) << r.err;
  std::ifstream in(dir / "r.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["settings"]["mode"], "pcb");
  EXPECT_GT(report["counts"]["lvoxels"].get<uint64_t>(), 1000u);
  EXPECT_GT(report["counts"]["surfels"].get<uint64_t>(), 10000u);
  for (const char* phase : {"surfel_sampling", "lvoxel_sampling", "octree_build", "direct_cache",
                            "interreflection", "gather_grid", "render"})
    EXPECT_TRUE(report["times"].contains(phase)) << phase;
  for (const char* mem : {"point_cloud", "octree", "lvoxel_light", "peak_rss"})
    EXPECT_GT(report["memory"][mem].get<uint64_t>(), 0u) << mem;
}

TEST(Scenes, RealSponzaRendersWhenPresent) {
  if (!fs::exists(std::string(LVOX_SHARED_DIR) + "/assets/sponza/sponza.obj"))
    GTEST_SKIP() << "shared Sponza asset absent";
  expectSceneRenders(std::string(LVOX_SOURCE_DIR) + "/scenes/sponza.json", "direct");
}

TEST(Scenes, OpenTownRendersWhenPresent) {
  for (const char* asset :
       {"bunny/bun_zipper.obj", "vdb/smoke.vdb", "vdb/wdas_cloud_sixteenth.vdb"})
    if (!fs::exists(std::string(LVOX_SHARED_DIR) + "/assets/" + asset))
      GTEST_SKIP() << "shared asset absent: " << asset;
  expectSceneRenders(std::string(LVOX_SOURCE_DIR) + "/scenes/open_town.json", "direct");
}

TEST(Scenes, LampHallRendersWhenPresent) {
  for (const char* asset : {"bunny/bun_zipper.obj", "vdb/smoke.vdb"})
    if (!fs::exists(std::string(LVOX_SHARED_DIR) + "/assets/" + asset))
      GTEST_SKIP() << "shared asset absent: " << asset;
  expectSceneRenders(std::string(LVOX_SOURCE_DIR) + "/scenes/lamp_hall.json", "direct");
}

TEST(Scenes, SunlitGalleryRendersWhenPresent) {
  for (const char* asset : {"bunny/bun_zipper.obj", "vdb/smoke.vdb"})
    if (!fs::exists(std::string(LVOX_SHARED_DIR) + "/assets/" + asset))
      GTEST_SKIP() << "shared asset absent: " << asset;
  expectSceneRenders(std::string(LVOX_SOURCE_DIR) + "/scenes/sunlit_gallery.json", "direct");
}

}  // namespace
}  // namespace lvox
