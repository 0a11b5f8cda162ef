// `lvox sweep` end to end: a small sweep as a regression check of the study (orders of the
// methods, auto's error, the Pareto front), and its handling of bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "app/run_lvox.h"
#include "test_util.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

// A point light in fog, just outside a small camera's view (rays pass it at h >= 0.5, so
// every method is in its asymptotic range at these steps).
const char* kScene = R"({
  "camera": {"position": [0, 0, 0], "look_at": [1, 0, 0], "vfov_deg": 40, "width": 12, "height": 12},
  "render": {"mode": "direct", "spp": 1},
  "lights": [{"type": "point", "position": [2, 1.5, 0], "intensity": 10}],
  "media": [{"type": "homogeneous", "min": [-1, -2, -2], "max": [5, 2, 2], "sigma_a": 0.3, "sigma_s": 0.4}],
  "volume_integrator": {"step": 0.1}
})";

using Row = std::map<std::string, std::string>;

std::vector<Row> readCsv(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> header;
  std::vector<Row> rows;
  auto split = [](const std::string& l) {
    std::vector<std::string> out;
    std::stringstream ss(l);
    for (std::string cell; std::getline(ss, cell, ',');) out.push_back(cell);
    return out;
  };
  if (std::getline(in, line)) header = split(line);
  while (std::getline(in, line)) {
    const std::vector<std::string> cells = split(line);
    Row r;
    for (size_t i = 0; i < header.size() && i < cells.size(); ++i) r[header[i]] = cells[i];
    rows.push_back(r);
  }
  return rows;
}

double delta(const std::vector<Row>& rows, const std::string& method, double value) {
  for (const Row& r : rows)
    if (r.at("method") == method && std::abs(std::stod(r.at("value")) - value) < 1e-6 * value)
      return std::stod(r.at("delta_percent"));
  ADD_FAILURE() << "no row " << method << " " << value;
  return 0.0;
}

TEST(SweepCli, WritesCsvAndPlotWithTheExpectedOrders) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  fs::create_directories(dir / "out");
  const RunResult r =
      runLvox("sweep " + (dir / "scene.json").string() + " -o " + (dir / "out").string() +
                  " --methods auto,euler,rk4 --step-scales 2,1 --tols 0.01,0.001",
              dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "out" / "sweep.png"));
  const std::vector<Row> rows = readCsv(dir / "out" / "sweep.csv");
  ASSERT_EQ(rows.size(), 6u);
  EXPECT_EQ(rows[0].at("parameter"), "tol");
  EXPECT_EQ(rows[2].at("parameter"), "step");
  for (const Row& row : rows) {
    EXPECT_EQ(row.at("invalid_samples"), "0");
    EXPECT_GT(std::stoull(row.at("medium_evals")), 0u);
  }
  // Euler is first order: halving the step halves the error (measured ratio 2.0).
  const double e2 = delta(rows, "euler", 0.2), e1 = delta(rows, "euler", 0.1);
  EXPECT_GT(e2 / e1, 1.6);
  EXPECT_LT(e2 / e1, 2.4);
  // RK4 at the same step is far more accurate; auto (equiangular Gauss-Kronrod) is at the
  // level of the fine reference (RK4 at step / 16) itself.
  EXPECT_LT(delta(rows, "rk4", 0.1), 0.1 * e1);
  EXPECT_LT(delta(rows, "auto", 0.001), 0.01);
  // The front: no row on it is beaten in both time and error by another row.
  int onFront = 0;
  for (const Row& a : rows) {
    if (a.at("pareto_evals") != "1") continue;
    ++onFront;
    for (const Row& b : rows)
      EXPECT_FALSE(std::stod(b.at("medium_evals")) < std::stod(a.at("medium_evals")) &&
                   std::stod(b.at("delta_percent")) < std::stod(a.at("delta_percent")));
  }
  EXPECT_GE(onFront, 1);
}

// A scene without a step: fixed-step methods sweep the scale of the media's own step, and
// halving it halves euler's error as halving an absolute step does.
TEST(SweepCli, ASceneWithoutAStepSweepsTheRelativeStep) {
  const auto dir = test::tempDir();
  std::string text = kScene;
  const std::string step = R"("volume_integrator": {"step": 0.1})";
  text.replace(text.find(step), step.size(), R"("volume_integrator": {"step_scale": 0.5})");
  test::writeFile(dir / "scene.json", text);
  fs::create_directories(dir / "out");
  const RunResult r =
      runLvox("sweep " + (dir / "scene.json").string() + " -o " + (dir / "out").string() +
                  " --methods euler --step-scales 2,1 --no-plot",
              dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const std::vector<Row> rows = readCsv(dir / "out" / "sweep.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("parameter"), "step_scale");
  EXPECT_EQ(rows[0].at("value"), "1");  // 2 x the scene's 0.5
  const double e2 = delta(rows, "euler", 1.0), e1 = delta(rows, "euler", 0.5);
  EXPECT_GT(e2 / e1, 1.6);
  EXPECT_LT(e2 / e1, 2.4);
}

void expectSweepFailure(const std::string& args, const std::string& field) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  fs::create_directories(dir / "out");
  const RunResult r = runLvox(
      "sweep " + (dir / "scene.json").string() + " -o " + (dir / "out").string() + " " + args, dir);
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find(field), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(dir / "out"));
}

TEST(SweepCli, UnknownMethod) { expectSweepFailure("--methods rk4,rk5", "--methods"); }
TEST(SweepCli, NotANumberTolerance) { expectSweepFailure("--tols 0.01,nan", "--tols"); }
TEST(SweepCli, MonteCarloWithoutSpp) { expectSweepFailure("--methods mc", "--mc-spp"); }
// Sweep values pass the checks of the scene fields they set (volume_integrator.tolerance is
// at most 1, the step at least 1e-6 units).
TEST(SweepCli, ValuesOutsideTheirFieldsRangesAreRefused) {
  expectSweepFailure("--methods dopri5 --tols 5", "--tols: value 5 is outside");
  expectSweepFailure("--methods rk4 --step-scales 1e-9", "--step-scales: value");
  expectSweepFailure("--mode nope", "--mode: unknown mode 'nope'");
  expectSweepFailure("--mode mc", "--mode: the sweep compares solvers");
}
TEST(SweepCli, ReferenceOfAnotherSize) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  fs::create_directories(dir / "out");
  ASSERT_EQ(runLvox("render " + (dir / "scene.json").string() + " --width 8 -o " +
                        (dir / "ref.exr").string(),
                    dir)
                .exitCode,
            0);
  const RunResult r =
      runLvox("sweep " + (dir / "scene.json").string() + " -o " + (dir / "out").string() +
                  " --reference " + (dir / "ref.exr").string() + " --methods rk4",
              dir);
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("--reference"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(dir / "out"));
}

}  // namespace
}  // namespace lvox
