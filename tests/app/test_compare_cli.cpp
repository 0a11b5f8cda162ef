// `lvox compare` end to end on images with known errors.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "src/core/exr_channels.h"
#include "src/core/image_io.h"
#include "test_util.h"

namespace lvox {
namespace {

std::string runCapture(const std::string& cmd, int& exitCode) {
  std::string out;
  FILE* pipe = popen(cmd.c_str(), "r");
  char buf[512];
  while (pipe && fgets(buf, sizeof(buf), pipe)) out += buf;
  const int status = pipe ? pclose(pipe) : -1;
  exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

TEST(CompareCli, JsonMetricsAndHeatmap) {
  const auto dir = test::tempDir();
  Image ref(4, 4, RGB(2.0f)), test(4, 4, RGB(2.0f));
  for (int x = 0; x < 4; ++x) test.at(x, 0) = RGB(2.8f);  // a quarter of the pixels +40 %
  writeExr((dir / "ref.exr").string(), ref);
  writeExr((dir / "test.exr").string(), test);
  int rc = -1;
  const std::string out = runCapture(
      std::string(LVOX_BINARY) + " compare " + (dir / "test.exr").string() + " " +
          (dir / "ref.exr").string() + " --json --heatmap " + (dir / "heat.png").string(),
      rc);
  ASSERT_EQ(rc, 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_NEAR(j["delta_percent"].get<double>(), 10.0, 1e-4);  // 0.25 * 40 %
  EXPECT_NEAR(j["max_abs"].get<double>(), 0.8, 1e-5);
  EXPECT_NEAR(j["rmse"].get<double>(), 0.4, 1e-5);  // sqrt(0.25 * 0.64)
  EXPECT_NEAR(j["mean_ratio"].get<double>(), 1.1, 1e-5);
  EXPECT_TRUE(std::filesystem::exists(dir / "heat.png"));
}

TEST(CompareCli, ErrorsAreOneLineAndNonZero) {
  const auto dir = test::tempDir();
  writeExr((dir / "a.exr").string(), Image(4, 4, RGB(1.0f)));
  writeExr((dir / "b.exr").string(), Image(5, 4, RGB(1.0f)));
  int rc = -1;
  std::string err = runCapture(std::string(LVOX_BINARY) + " compare " + (dir / "a.exr").string() +
                                   " " + (dir / "b.exr").string() + " 2>&1",
                               rc);
  EXPECT_NE(rc, 0);
  EXPECT_NE(err.find("a.exr"), std::string::npos) << err;
  err = runCapture(std::string(LVOX_BINARY) + " compare " + (dir / "a.exr").string() + " " +
                       (dir / "none.exr").string() + " 2>&1",
                   rc);
  EXPECT_NE(rc, 0);
  EXPECT_NE(err.find("none.exr"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

// `--layer` picks one layer of a multi-layer EXR; a Cycles-style "ViewLayer.Combined.R"
// matches `--layer Combined`; a missing layer names the layers the file has.
TEST(CompareCli, LayerOfMultiLayerExr) {
  const auto dir = test::tempDir();
  auto file = [&](const std::string& name, const std::string& layer, float value, float depth) {
    ExrChannels c;
    c.width = 4;
    c.height = 4;
    for (const char* n : {"R", "G", "B"}) {
      c.names.push_back(n);
      c.planes.emplace_back(16, 1.0f);
      c.names.push_back(layer + "." + n);
      c.planes.emplace_back(16, value);
    }
    c.names.push_back("depth.Z");
    c.planes.emplace_back(16, depth);
    writeExrChannels((dir / name).string(), c);
  };
  file("a.exr", "ViewLayer.Combined", 2.2f, 3.0f);
  file("b.exr", "ViewLayer.Combined", 2.0f, 2.0f);
  int rc = -1;
  const std::string base = std::string(LVOX_BINARY) + " compare " + (dir / "a.exr").string() + " " +
                           (dir / "b.exr").string() + " --json";
  nlohmann::json j = nlohmann::json::parse(runCapture(base + " --layer Combined", rc));
  ASSERT_EQ(rc, 0);
  EXPECT_NEAR(j["mean_ratio"].get<double>(), 1.1, 1e-5);
  EXPECT_NEAR(j["max_abs"].get<double>(), 0.2, 1e-5);
  j = nlohmann::json::parse(runCapture(base + " --layer depth", rc));
  ASSERT_EQ(rc, 0);
  EXPECT_NEAR(j["mean_ratio"].get<double>(), 1.5, 1e-5);
  j = nlohmann::json::parse(runCapture(base, rc));  // no --layer: the colour R, G, B
  ASSERT_EQ(rc, 0);
  EXPECT_NEAR(j["max_abs"].get<double>(), 0.0, 1e-7);
  const std::string err = runCapture(base + " --layer albedo 2>&1", rc);
  EXPECT_NE(rc, 0);
  EXPECT_NE(err.find("albedo"), std::string::npos) << err;
  EXPECT_NE(err.find("ViewLayer.Combined"), std::string::npos) << err;
  EXPECT_NE(err.find("depth"), std::string::npos) << err;
}

// compare reads any image OpenImageIO reads: two 8-bit PNGs, values as stored (0..1).
TEST(CompareCli, ReadsPng) {
  const auto dir = test::tempDir();
  writePngRgb8((dir / "a.png").string(), 2, 2, std::vector<uint8_t>(12, 102));
  writePngRgb8((dir / "b.png").string(), 2, 2, std::vector<uint8_t>(12, 51));
  int rc = -1;
  const nlohmann::json j = nlohmann::json::parse(
      runCapture(std::string(LVOX_BINARY) + " compare " + (dir / "a.png").string() + " " +
                     (dir / "b.png").string() + " --json",
                 rc));
  ASSERT_EQ(rc, 0);
  EXPECT_NEAR(j["mean_ratio"].get<double>(), 2.0, 1e-5);
  EXPECT_NEAR(j["max_abs"].get<double>(), 0.2, 1e-5);  // (102 - 51) / 255
}

}  // namespace
}  // namespace lvox
