// `lvox render --layers` and `lvox merge` of layered chunks: the layers land in the one EXR
// under their names; two chunks merge to the layers of one render of all their samples
// (the variance recombined from the chunks' moments); a chunk with other layers, an unknown
// layer and the variance outside mc are refused with one line, writing nothing.
#include <gtest/gtest.h>

#include <filesystem>

#include "app/run_lvox.h"
#include "src/core/exr_channels.h"
#include "test_util.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

const char* kScene = R"({
  "camera": {"position": [0, 2, 4], "look_at": [0, 0, 0], "vfov_deg": 40, "width": 24, "height": 16},
  "render": {"mode": "mc", "spp": 4, "max_bounces": 3},
  "materials": {"white": {"albedo": 0.7}},
  "shapes": [{"type": "quad", "corners": [[-2,0,-2],[2,0,-2],[2,0,2],[-2,0,2]], "material": "white"},
             {"type": "box", "min": [-0.3,0,-0.3], "max": [0.3,0.6,0.3], "material": "white"}],
  "lights": [{"type": "directional", "direction": [0.3, -1, -0.2], "irradiance": 3},
             {"type": "environment", "radiance": 0.1}],
  "media": [{"type": "homogeneous", "min": [-1, 0, -1], "max": [1, 1, 1], "sigma_s": 0.5}]
})";

class LayersCli : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::tempDir();
    test::writeFile(dir_ / "scene.json", kScene);
  }
  RunResult render(const std::string& args, const std::string& out) {
    return runLvox("render " + scene() + " " + args + " -o " + path(out), dir_);
  }
  std::string scene() const { return (dir_ / "scene.json").string(); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(LayersCli, ChunksMergeToTheLayersOfOneRender) {
  ASSERT_EQ(render("--layers all --spp 8", "whole.exr").exitCode, 0);
  ASSERT_EQ(render("--layers all --spp 3", "a.exr").exitCode, 0);
  ASSERT_EQ(render("--layers all --spp 5 --first-sample 3", "b.exr").exitCode, 0);
  const RunResult merge =
      runLvox("merge " + path("a.exr") + " " + path("b.exr") + " -o " + path("merged.exr"), dir_);
  ASSERT_EQ(merge.exitCode, 0) << merge.err;
  const ExrChannels whole = readExrChannels(path("whole.exr"));
  const ExrChannels merged = readExrChannels(path("merged.exr"));
  EXPECT_EQ(whole.metadata.at("lvox.layers"),
            "direct,indirect,volume,emission,environment,albedo,normal,depth,variance");
  for (const char* name : {"R", "direct.R", "indirect.G", "volume.B", "environment.R", "albedo.G",
                           "normal.Y", "depth.Z", "coverage.Y", "variance.R"})
    ASSERT_NE(whole.find(name), nullptr) << name;
  ASSERT_EQ(whole.names, merged.names);
  double varianceSum = 0.0;
  for (size_t c = 0; c < whole.names.size(); ++c) {
    const std::vector<float>& w = whole.planes[c];
    const std::vector<float>& m = *merged.find(whole.names[c]);
    for (size_t i = 0; i < w.size(); ++i) {
      // The same samples, summed in another order: float rounding only (the variance
      // through the chunks' float means: 1e-4 of the mean square).
      const float tol = whole.names[c].starts_with("variance") ? 1e-4f : 1e-5f;
      ASSERT_NEAR(m[i], w[i], tol * (std::abs(w[i]) + 1e-2f)) << whole.names[c] << " " << i;
    }
    if (whole.names[c] == "variance.R")
      for (float v : w) varianceSum += v;
  }
  EXPECT_GT(varianceSum, 0.0);  // noisy pixels have a variance
}

TEST_F(LayersCli, MismatchedUnknownAndMisplacedLayersAreRefused) {
  ASSERT_EQ(render("--layers direct --spp 2", "a.exr").exitCode, 0);
  ASSERT_EQ(render("--spp 2 --first-sample 2", "b.exr").exitCode, 0);
  RunResult r =
      runLvox("merge " + path("a.exr") + " " + path("b.exr") + " -o " + path("m.exr"), dir_);
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("lvox.layers"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("m.exr")));

  r = render("--layers direct,specular", "c.exr");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("unknown layer 'specular'"), std::string::npos) << r.err;
  r = render("--mode pcb --layers variance", "d.exr");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("--layers: variance"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("c.exr")));
  EXPECT_FALSE(fs::exists(path("d.exr")));
}

}  // namespace
}  // namespace lvox
