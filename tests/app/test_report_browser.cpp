// `lvox report` in a real browser: headless Chromium opens the page with #selftest, which
// drives the slider, the exposure, the layers, the error map and the cursor readout and
// writes what it measured into the DOM; this test compares those numbers with the EXRs it
// wrote, checks that plots and tables are drawn, that nothing went to the console as an
// error, and that a screenshot of the page is not blank.
#include <gtest/gtest.h>
#include <png.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "app/report_fixture.h"
#include "src/core/image_metrics.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

constexpr int kX = 5, kY = 3;  // the probed pixel
constexpr float kEv = 1.0f;    // the exposure the self-test sets

std::string chromium() {
  if (const char* env = std::getenv("LVOX_CHROMIUM")) return env;
  for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
    if (fs::exists(p)) return p;
  return "";
}

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs headless Chromium on `url` with `mode` (--dump-dom or --screenshot=...); stdout to
// `out`, the browser's log (console messages included) to `log`.
int runChromium(const fs::path& dir, const std::string& mode, const std::string& url,
                const fs::path& out, const fs::path& log) {
  const std::string cmd =
      "timeout 120 " + chromium() +
      " --headless=new --no-sandbox --disable-gpu --disable-dev-shm-usage --disable-quic"
      " --no-first-run --disable-background-networking --disable-component-update"
      " --disable-sync --hide-scrollbars --user-data-dir=" +
      (dir / "profile").string() +
      " --window-size=1280,1800 --virtual-time-budget=10000 --enable-logging=stderr --v=0 " + mode +
      " '" + url + "' >" + out.string() + " 2>" + log.string();
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string unescapeHtml(std::string s) {
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"&lt;", "<"},
                                 {"&gt;", ">"},
                                 {"&quot;", "\""},
                                 {"&amp;", "&"}})
    for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + 1))
      s.replace(at, from.size(), to);
  return s;
}

nlohmann::json selfTestResult(const std::string& dom) {
  const std::string open = "<pre id=\"selftest-result\">";
  const size_t begin = dom.rfind(open);  // the element, after the scripts
  if (begin == std::string::npos) return nullptr;
  const size_t end = dom.find("</pre>", begin);
  return nlohmann::json::parse(
      unescapeHtml(dom.substr(begin + open.size(), end - begin - open.size())));
}

std::array<int, 3> shown(RGB v, float ev) {
  const float k = std::pow(2.0f, ev);
  return {toneMap(v[0], k), toneMap(v[1], k), toneMap(v[2], k)};
}

void expectPixel(const nlohmann::json& got, std::array<int, 3> want, const std::string& what) {
  ASSERT_TRUE(got.is_array()) << what;
  for (size_t c = 0; c < 3; ++c)
    EXPECT_NEAR(got[c].get<int>(), want[c], 1) << what << " channel " << c;
}

// "A render.exr: R=0.255  G=0.375  B=0.225" -> the value after "NAME=".
double readoutValue(const std::string& line, const std::string& name) {
  std::smatch m;
  if (!std::regex_search(line, m, std::regex("(^|\\s)" + name + "=([-0-9.e+]+)"))) {
    ADD_FAILURE() << "no " << name << "= in '" << line << "'";
    return NAN;
  }
  return std::stod(m[2].str());
}

struct Inputs {
  fs::path page;
  size_t sweepRows = 0, frontTime = 0, frontEvals = 0, autoRows = 0, convergenceRows = 0;
  double renderSeconds = 0.0;
};

// Runs lvox to make a sweep, two render reports and a convergence curve, then the report.
Inputs makeReport(const fs::path& dir) {
  test::writeReference(dir / "ref.exr");
  test::writeLayeredRender(dir / "render.exr");
  writeExr((dir / "second.exr").string(), Image(test::kWidth, test::kHeight, RGB(0.25f)));
  test::writeFile(dir / "scene.json", test::kFogScene);
  fs::create_directories(dir / "sweep");
  const std::string scene = (dir / "scene.json").string();
  for (const std::string& args :
       {"sweep " + scene + " -o " + (dir / "sweep").string() +
            " --methods auto,euler,rk4 --step-scales 2,1 --tols 0.01,0.001 --no-plot -q",
        "render " + scene + " -q -o " + (dir / "direct.exr").string() + " --report " +
            (dir / "direct.json").string(),
        "render " + scene + " -q --mode mc --spp 8 -o " + (dir / "mc.exr").string() + " --report " +
            (dir / "mc.json").string() + " --convergence " +
            (dir / "sweep" / "reference.exr").string() + " --convergence-csv " +
            (dir / "conv.csv").string(),
        "report " + (dir / "render.exr").string() + " " + (dir / "second.exr").string() +
            " --reference " + (dir / "ref.exr").string() + " --sweep " + (dir / "sweep").string() +
            " --convergence " + (dir / "conv.csv").string() + " --reports " +
            (dir / "direct.json").string() + " " + (dir / "mc.json").string() + " -q -o " +
            (dir / "report.html").string()}) {
    const RunResult r = runLvox(args, dir);
    EXPECT_EQ(r.exitCode, 0) << args << "\n" << r.err;
  }
  Inputs in;
  in.page = dir / "report.html";
  std::ifstream csv(dir / "sweep" / "sweep.csv");
  std::string line;
  std::getline(csv, line);
  while (std::getline(csv, line)) {
    ++in.sweepRows;
    in.frontTime += line.substr(line.size() - 3, 1) == "1";
    in.frontEvals += line.back() == '1';
    in.autoRows += line.find(",auto,") != std::string::npos;
  }
  std::ifstream conv(dir / "conv.csv");
  for (std::getline(conv, line); std::getline(conv, line);) ++in.convergenceRows;
  in.renderSeconds = nlohmann::json::parse(readText(dir / "direct.json"))["times"]["total"];
  return in;
}

void checkViewer(const nlohmann::json& v) {
  const RGB a = test::renderPixel(kX, kY), b = test::referencePixel(kX, kY);
  EXPECT_EQ(v["sidePanes"], 2);
  EXPECT_GT(v["distinctColours"].get<int>(), 50);  // the gradient is drawn, not a blank pane
  expectPixel(v["sliderAtA"], shown(a, 0.0f), "slider at A");
  expectPixel(v["sliderAtB"], shown(b, 0.0f), "slider at B");
  EXPECT_NE(v["sliderAtA"], v["sliderAtB"]);
  expectPixel(v["exposure"]["atA"], shown(a, kEv), "A at +1 EV");
  expectPixel(v["exposure"]["atB"], shown(b, kEv), "B at +1 EV");
  EXPECT_NE(v["exposure"]["atA"], v["sliderAtA"]);
  ASSERT_EQ(v["flip"].size(), 2u);  // flip shows A, then B
  EXPECT_EQ(v["flip"][0], v["exposure"]["atA"]);
  EXPECT_EQ(v["flip"][1], v["exposure"]["atB"]);
  const std::vector<std::string> readout = v["readout"];
  EXPECT_EQ(readout[0], "pixel (5, 3)");
  for (int c = 0; c < 3; ++c) {
    const std::string name(1, "RGB"[c]);
    EXPECT_NEAR(readoutValue(readout[1], name), a[c], 1e-5 * a[c]) << readout[1];
    EXPECT_NEAR(readoutValue(readout[2], name), b[c], 1e-5 * b[c]) << readout[2];
  }
  // Layers: albedo as RGB, depth.Z as grey.
  int checkedLayers = 0;
  for (const nlohmann::json& layer : v["layers"]) {
    if (layer["value"] == "rgb:albedo") {
      expectPixel(layer["atA"], shown(test::albedoPixel(kX, kY), kEv), "albedo");
      ++checkedLayers;
    }
    if (layer["value"] == "ch:depth.Z") {
      const float z = test::depthPixel(kX, kY);
      expectPixel(layer["atA"], shown(RGB(z), kEv), "depth");
      EXPECT_NEAR(readoutValue(layer["readout"], "Z"), z, 1e-6) << layer["readout"];
      ++checkedLayers;
    }
  }
  EXPECT_EQ(checkedLayers, 2);
  // The error map's value under the cursor is the relative error of `lvox compare`.
  Image ia(1, 1, a), ib(1, 1, b);
  const double err = relativeErrorMap(ia, ib)[0];
  EXPECT_NEAR(readoutValue(v["errorMap"]["readout"], "error"), err, 1e-5 * err);
}

// A PNG with many colours and not mostly white: something was drawn.
void expectNotBlank(const fs::path& png) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&image, png.c_str())) << png;
  image.format = PNG_FORMAT_RGB;
  std::vector<uint8_t> rgb(PNG_IMAGE_SIZE(image));
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr));
  std::set<uint32_t> colours;
  size_t notWhite = 0;
  for (size_t i = 0; i + 2 < rgb.size(); i += 3) {
    colours.insert(uint32_t{rgb[i]} << 16 | uint32_t{rgb[i + 1]} << 8 | rgb[i + 2]);
    notWhite += rgb[i] < 240 || rgb[i + 1] < 240 || rgb[i + 2] < 240;
  }
  EXPECT_GT(colours.size(), 100u);
  EXPECT_GT(static_cast<double>(notWhite) / static_cast<double>(rgb.size() / 3), 0.1);
}

TEST(ReportBrowser, SelfTestInHeadlessChromium) {
  if (chromium().empty())
    GTEST_SKIP() << "chromium is not installed (Debian package chromium; .ci/setup installs it)";
  const auto dir = test::tempDir();
  const Inputs in = makeReport(dir);
  ASSERT_TRUE(fs::exists(in.page));
  const std::string url = "file://" + fs::absolute(in.page).string();
  ASSERT_EQ(runChromium(dir, "--dump-dom", url + "#selftest&x=5&y=3&ev=1", dir / "dom.html",
                        dir / "chromium.log"),
            0)
      << readText(dir / "chromium.log");
  const nlohmann::json r = selfTestResult(readText(dir / "dom.html"));
  ASSERT_FALSE(r.is_null()) << "no self-test result in the DOM\n" << readText(dir / "chromium.log");
  EXPECT_TRUE(r["errors"].empty()) << r["errors"].dump(1);
  const std::string log = readText(dir / "chromium.log");
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
  EXPECT_EQ(log.find(":ERROR:CONSOLE"), std::string::npos) << log;
  ASSERT_TRUE(r.contains("viewer"));
  checkViewer(r["viewer"]);

  ASSERT_EQ(r["plots"].size(), 2u);  // the sweep and the convergence curves
  const nlohmann::json& sweep = r["plots"][0];
  ASSERT_EQ(sweep["plots"].size(), 2u);
  EXPECT_EQ(sweep["plots"][0]["points"], in.sweepRows);
  EXPECT_EQ(sweep["plots"][1]["points"], in.sweepRows);
  EXPECT_EQ(sweep["plots"][0]["front"], in.frontTime);  // the page's front is sweep's
  EXPECT_EQ(sweep["plots"][1]["front"], in.frontEvals);
  EXPECT_EQ(sweep["plots"][0]["bold"], in.autoRows);
  const std::string tooltip = sweep["plots"][0]["tooltip"];
  // The first point drawn of euler's series: which of its steps comes first depends on the
  // measured times (the x axis), so only the parameter's name is fixed.
  for (const char* word : {"euler", "step = 0.", "time", "evaluations", "delta"})
    EXPECT_NE(tooltip.find(word), std::string::npos) << word << " not in " << tooltip;
  EXPECT_EQ(sweep["thumbs"], 1 + 2 * in.sweepRows);  // reference, then image + error map
  EXPECT_GT(sweep["thumbColours"][0].get<int>(), 4);
  EXPECT_EQ(r["plots"][1]["plots"][0]["points"], in.convergenceRows);

  // Tables: the render's error and the report's total time, as shown.
  ASSERT_EQ(r["metrics"].size(), 3u);  // header, render.exr, second.exr
  EXPECT_EQ(r["metrics"][1][0], "render.exr");
  EXPECT_EQ(r["metrics"][1][2], "50");
  bool total = false;
  for (const nlohmann::json& row : r["times"])
    if (row[0] == "total") {
      total = true;
      EXPECT_NEAR(std::stod(row[1].get<std::string>()), in.renderSeconds, 1e-3 * in.renderSeconds);
    }
  EXPECT_TRUE(total) << r["times"].dump();

  ASSERT_EQ(runChromium(dir, "--screenshot=" + (dir / "shot.png").string(), url, dir / "stdout.txt",
                        dir / "shot.log"),
            0)
      << readText(dir / "shot.log");
  expectNotBlank(dir / "shot.png");
}

}  // namespace
}  // namespace lvox
