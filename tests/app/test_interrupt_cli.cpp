// Ctrl-C during a Monte Carlo render keeps the finished samples as a valid image that
// merges with a resumed run; a second Ctrl-C quits at once and leaves nothing behind.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "app/run_lvox.h"
#include "src/core/image_io.h"
#include "src/core/image_metrics.h"
#include "test_util.h"

extern char** environ;

namespace lvox {
namespace {

namespace fs = std::filesystem;

const char* kScene = R"({
  "camera": {"position": [0, 2, 4], "look_at": [0, 0, 0], "vfov_deg": 40, "width": 24, "height": 16},
  "render": {"mode": "mc", "spp": 1000000, "max_bounces": 4},
  "materials": {"white": {"albedo": 0.7}},
  "shapes": [{"type": "quad", "corners": [[-2,0,-2],[2,0,-2],[2,0,2],[-2,0,2]], "material": "white"}],
  "lights": [{"type": "environment", "radiance": 0.5}]
})";

// Starts lvox with `args`, sends SIGINT `signals` times (the first after `wait`), and
// returns the exit status (128 + signal when killed by one, as a shell reports it).
int renderInterrupted(const std::vector<std::string>& args, std::chrono::milliseconds wait,
                      int signals, const fs::path& dir) {
  std::vector<std::string> all{LVOX_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  const std::string err = (dir / "stderr.txt").string();
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  EXPECT_EQ(posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  std::this_thread::sleep_for(wait);
  for (int i = 0; i < signals; ++i) {
    kill(pid, SIGINT);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

uint64_t sppOf(const fs::path& exr) {
  ImageMetadata meta;
  readExr(exr.string(), &meta);
  return std::stoull(meta.at("lvox.spp"));
}

TEST(InterruptCli, CtrlCKeepsTheFinishedSamplesAndTheyMergeWithAResumedRun) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  const std::string scene = (dir / "scene.json").string();
  const int rc = renderInterrupted({"render", scene, "-o", (dir / "a.exr").string()},
                                   std::chrono::milliseconds(2500), 1, dir);
  EXPECT_EQ(rc, 130);
  ASSERT_TRUE(fs::exists(dir / "a.exr"));
  const uint64_t done = sppOf(dir / "a.exr");
  EXPECT_GT(done, 0u);
  EXPECT_LT(done, 1000000u);
  // The rest of a 64-sample longer render, resumed where the interrupted one stopped.
  ASSERT_EQ(runLvox("render " + scene + " --spp 64 --first-sample " + std::to_string(done) +
                        " -o " + (dir / "b.exr").string(),
                    dir)
                .exitCode,
            0);
  ASSERT_EQ(runLvox("merge " + (dir / "a.exr").string() + " " + (dir / "b.exr").string() + " -o " +
                        (dir / "merged.exr").string(),
                    dir)
                .exitCode,
            0);
  ASSERT_EQ(runLvox("render " + scene + " --spp " + std::to_string(done + 64) + " -o " +
                        (dir / "full.exr").string(),
                    dir)
                .exitCode,
            0);
  EXPECT_EQ(sppOf(dir / "merged.exr"), done + 64);
  // Same samples, summed in another order: equal to float rounding.
  EXPECT_LT(
      compareImages(readExr((dir / "merged.exr").string()), readExr((dir / "full.exr").string()))
          .maxAbs,
      1e-4);
}

TEST(InterruptCli, ASecondCtrlCQuitsAtOnceLeavingNothing) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "scene.json", kScene);
  const int rc =
      renderInterrupted({"render", (dir / "scene.json").string(), "-o", (dir / "a.exr").string()},
                        std::chrono::milliseconds(1500), 2, dir);
  EXPECT_EQ(rc, 128 + SIGINT);
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
}

}  // namespace
}  // namespace lvox
