// `lvox report` without a browser: what the page embeds, determinism, the sweep's kept
// images and report, downsampling of large images, and bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/report_fixture.h"
#include "src/app/base64.h"
#include "src/app/report_images.h"
#include "src/core/image_metrics.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The JSON the page embeds, as the page reads it.
nlohmann::json embeddedData(const std::string& page) {
  const std::string open = "<script type=\"application/json\" id=\"lvox-data\">";
  const size_t begin = page.find(open);
  const size_t end = page.find("</script>", begin);
  EXPECT_NE(begin, std::string::npos);
  return nlohmann::json::parse(page.substr(begin + open.size(), end - begin - open.size()));
}

TEST(Base64, FloatsAreLittleEndian) {
  EXPECT_EQ(base64Floats({1.0f}), "AACAPw==");             // 00 00 80 3f
  EXPECT_EQ(base64Floats({1.0f, -2.0f}), "AACAPwAAAMA=");  // ... 00 00 00 c0
  EXPECT_EQ(base64Floats({}), "");
}

TEST(ReportCli, EmbedsEveryLayerAndTheErrorsAndIsDeterministic) {
  const auto dir = test::tempDir();
  test::writeReference(dir / "ref.exr");
  test::writeLayeredRender(dir / "render.exr");
  const std::string args = "report " + (dir / "render.exr").string() + " --reference " +
                           (dir / "ref.exr").string() + " --title 'a <b>' -o ";
  ASSERT_EQ(runLvox(args + (dir / "a.html").string(), dir).exitCode, 0);
  ASSERT_EQ(runLvox(args + (dir / "b.html").string(), dir).exitCode, 0);
  const std::string page = readText(dir / "a.html");
  EXPECT_EQ(page, readText(dir / "b.html"));
  EXPECT_NE(page.find("<title>a &lt;b&gt;</title>"), std::string::npos);
  EXPECT_EQ(page.find("<script src"), std::string::npos);  // self-contained
  EXPECT_EQ(page.find("<link"), std::string::npos);
  const nlohmann::json data = embeddedData(page);
  ASSERT_EQ(data["images"].size(), 2u);
  EXPECT_EQ(data["reference"], 1);
  const nlohmann::json& render = data["images"][0];
  EXPECT_EQ(render["layers"].dump(),
            R"([{"channels":["R","G","B"],"name":""},)"
            R"({"channels":["albedo.R","albedo.G","albedo.B"],"name":"albedo"},)"
            R"({"channels":["depth.Z"],"name":"depth"}])");
  EXPECT_EQ(render["width"], test::kWidth);
  EXPECT_EQ(render["scale"], 1);
  // The render is 1.5 times the reference: delta 50 %, mean ratio 1.5.
  EXPECT_NEAR(render["metrics"]["delta_percent"].get<double>(), 50.0, 1e-3);
  EXPECT_NEAR(render["metrics"]["mean_ratio"].get<double>(), 1.5, 1e-6);
  // The first row of depth.Z: 0, 0.25, 0.5, ... (12 bytes, 16 base64 digits).
  EXPECT_EQ(render["channels"]["depth.Z"].get<std::string>().substr(0, 16),
            base64Floats({0.0f, 0.25f, 0.5f}));
  EXPECT_TRUE(data["notes"].empty());
}

TEST(ReportCli, SweepKeepsEachPointsImageAndErrorMapAndWritesItsReport) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", test::kFogScene);
  fs::create_directories(dir / "out");
  const RunResult r =
      runLvox("sweep " + (dir / "scene.json").string() + " -o " + (dir / "out").string() +
                  " --methods auto,euler --step-scales 2,1 --tols 0.01 --no-plot -q",
              dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "out" / "reference.exr"));
  const ExrChannels euler =
      readExrChannels((dir / "out" / "points" / "002_euler_step_0.1.exr").string());
  ASSERT_NE(euler.find("error.Y"), nullptr);
  // The kept error map is the one `lvox compare` measures against the kept reference.
  const Image ref = readExr((dir / "out" / "reference.exr").string());
  const std::vector<float> expected = relativeErrorMap(*colourImage(euler), ref);
  EXPECT_EQ(*euler.find("error.Y"), expected);
  const nlohmann::json data = embeddedData(readText(dir / "out" / "report.html"));
  ASSERT_EQ(data["sweeps"].size(), 1u);
  const nlohmann::json& sweep = data["sweeps"][0];
  ASSERT_EQ(sweep["rows"].size(), 3u);
  EXPECT_EQ(sweep["thumbs"]["points"].size(), 3u);
  EXPECT_EQ(sweep["thumbs"]["width"], 12);
  EXPECT_FALSE(sweep["thumbs"]["points"][1]["error"].is_null());
  // The viewer holds the reference and the time front's points.
  EXPECT_GE(data["images"].size(), 2u);
  EXPECT_EQ(data["images"].back()["role"], "reference");
}

TEST(ReportImages, LargeImagesAreDownsampledAndSaySo) {
  const auto dir = test::tempDir();
  // 2 x 2100 x 1000 pixels is more than 4 MPixel: shown at half size, errors at full size.
  Image ref(2100, 1000, RGB(1.0f)), test(2100, 1000, RGB(1.0f));
  test.at(2099, 999) = RGB(2.0f);
  writeExr((dir / "ref.exr").string(), ref);
  writeExr((dir / "test.exr").string(), test);
  std::vector<std::string> notes;
  const nlohmann::json data =
      reportImages({(dir / "test.exr").string()}, (dir / "ref.exr").string(), notes);
  EXPECT_EQ(data["images"][0]["width"], 1050);
  EXPECT_EQ(data["images"][0]["height"], 500);
  EXPECT_EQ(data["images"][0]["scale"], 2);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("1:2"), std::string::npos);
  EXPECT_NEAR(data["images"][0]["metrics"]["max_abs"].get<double>(), 1.0, 1e-6);
}

// Bad input: one line naming the file and field, non-zero exit, no page.
void expectReportFailure(const fs::path& dir, const std::string& args, const std::string& text) {
  const RunResult r = runLvox("report " + args + " -o " + (dir / "r.html").string(), dir);
  EXPECT_NE(r.exitCode, 0);
  EXPECT_EQ(r.err.rfind("lvox: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(text), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir / "r.html"));
}

TEST(ReportCli, BadInputIsOneLineAndWritesNothing) {
  const auto dir = test::tempDir();
  test::writeReference(dir / "ref.exr");
  writeExr((dir / "small.exr").string(), Image(4, 4, RGB(1.0f)));
  fs::create_directories(dir / "nosweep");
  fs::create_directories(dir / "badsweep");
  test::writeFile(dir / "badsweep" / "sweep.csv",
                  "method,parameter,value,seconds,medium_evals,delta_percent\n"
                  "rk4,step,0.1,1.5,100,2\nrk4,step,0.05,fast,200,1\n");
  test::writeFile(dir / "report.json", R"({"times": {"render": "slow"}})");
  test::writeFile(dir / "conv.csv", "spp,seconds\n1,0.5\n");
  expectReportFailure(dir, "", "nothing to report");
  expectReportFailure(dir, (dir / "missing.exr").string(), "missing.exr");
  expectReportFailure(dir,
                      (dir / "small.exr").string() + " --reference " + (dir / "ref.exr").string(),
                      "small.exr");
  expectReportFailure(dir, "--sweep " + (dir / "nosweep").string(), "no sweep.csv");
  expectReportFailure(dir, "--sweep " + (dir / "badsweep").string(), "line 3: seconds");
  expectReportFailure(dir, "--reports " + (dir / "report.json").string(), "times.render");
  expectReportFailure(dir, "--convergence " + (dir / "conv.csv").string(), "delta_percent");
  const RunResult notHtml =
      runLvox("report " + (dir / "ref.exr").string() + " -o " + (dir / "r.exr").string(), dir);
  EXPECT_NE(notHtml.exitCode, 0);
  EXPECT_NE(notHtml.err.find(".html"), std::string::npos) << notHtml.err;
}

}  // namespace
}  // namespace lvox
