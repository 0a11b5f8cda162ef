// `lvox merge` with a chunk missing (a cluster task that died): it names the sample ranges
// no chunk holds; with --expect-spp it writes nothing until they are rendered, and
// re-rendering only them completes the image.
#include <gtest/gtest.h>

#include <filesystem>

#include "app/run_lvox.h"
#include "src/core/image_io.h"
#include "src/core/image_metrics.h"
#include "test_util.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

const char* kScene = R"({
  "camera": {"position": [0, 2, 4], "look_at": [0, 0, 0], "vfov_deg": 40, "width": 24, "height": 16},
  "render": {"mode": "mc", "spp": 2, "max_bounces": 3},
  "materials": {"white": {"albedo": 0.7}},
  "shapes": [{"type": "quad", "corners": [[-2,0,-2],[2,0,-2],[2,0,2],[-2,0,2]], "material": "white"},
             {"type": "box", "min": [-0.3,0,-0.3], "max": [0.3,0.6,0.3], "material": "white"}],
  "lights": [{"type": "directional", "direction": [0.3, -1, -0.2], "irradiance": 3},
             {"type": "environment", "radiance": 0.1}]
})";

class MergeGaps : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::tempDir();
    test::writeFile(dir_ / "scene.json", kScene);
  }
  // Renders chunk `task`: samples [2 task, 2 task + 2), as docs/cluster/reference-chunks.sbatch.
  void renderChunk(int task) {
    const RunResult r = runLvox("render " + (dir_ / "scene.json").string() + " --first-sample " +
                                    std::to_string(2 * task) + " -o " + chunk(task),
                                dir_);
    ASSERT_EQ(r.exitCode, 0) << r.err;
  }
  std::string chunk(int task) const {
    return (dir_ / ("chunk-" + std::to_string(task) + ".exr")).string();
  }
  std::string out() const { return (dir_ / "merged.exr").string(); }
  fs::path dir_;
};

TEST_F(MergeGaps, NamesTheMissingRangeAndMergesOnceItIsRendered) {
  renderChunk(0);
  renderChunk(2);
  renderChunk(4);  // tasks 1 and 3 died
  const std::string chunks = chunk(0) + " " + chunk(2) + " " + chunk(4);

  // Expecting samples [0, 12): [2, 4), [6, 8) and [10, 12) are missing; nothing is written.
  RunResult r = runLvox("merge " + chunks + " --expect-spp 12 -o " + out(), dir_);
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("--expect-spp: samples [2, 4) (--first-sample 2 --spp 2), [6, 8) "
                       "(--first-sample 6 --spp 2), [10, 12) (--first-sample 10 --spp 2) are "
                       "missing"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out()));

  // Without an expectation the samples present are a valid image; the gaps are named.
  r = runLvox("merge " + chunks + " -o " + out(), dir_);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("warning: no chunk holds samples [2, 4) (--first-sample 2 --spp 2), "
                       "[6, 8) (--first-sample 6 --spp 2)"),
            std::string::npos)
      << r.err;
  fs::remove(out());

  // Only the missing chunks again: the merge equals one render of samples [0, 10).
  renderChunk(1);
  renderChunk(3);
  r = runLvox("merge " + chunks + " " + chunk(1) + " " + chunk(3) + " --expect-spp 10 -o " + out(),
              dir_);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  ASSERT_EQ(runLvox("render " + (dir_ / "scene.json").string() + " --spp 10 -o " +
                        (dir_ / "full.exr").string(),
                    dir_)
                .exitCode,
            0);
  // The same samples summed in another order: equal to float rounding (radiance ~1).
  EXPECT_LT(compareImages(readExr(out()), readExr((dir_ / "full.exr").string())).maxAbs, 1e-5);

  // A chunk beyond the expected samples is named.
  r = runLvox("merge " + chunks + " --expect-spp 8 -o " + (dir_ / "short.exr").string(), dir_);
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("beyond --expect-spp 8"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace lvox
