// Outputs published together: all or none, and no temporary left behind on a failure or
// a signal.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "src/core/atomic_file.h"
#include "src/core/error.h"
#include "test_util.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

WriteFn text(const std::string& content) {
  return [content](const std::string& tmp) { std::ofstream(tmp) << content; };
}

size_t fileCount(const fs::path& dir) {
  size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.is_regular_file() ? 1 : 0;
  return n;
}

TEST(OutputSet, PublishesEveryFileOnlyAtCommit) {
  const auto dir = test::tempDir();
  OutputSet set;
  set.stage((dir / "a.txt").string(), text("a"));
  set.stage((dir / "b.txt").string(), text("b"));
  EXPECT_FALSE(fs::exists(dir / "a.txt"));
  EXPECT_FALSE(fs::exists(dir / "b.txt"));
  set.commit();
  EXPECT_TRUE(fs::exists(dir / "a.txt"));
  EXPECT_TRUE(fs::exists(dir / "b.txt"));
  EXPECT_EQ(fileCount(dir), 2u);  // no temporaries left
}

TEST(OutputSet, AFailedFileLeavesNothingOfTheSet) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "a.txt", "previous");
  {
    OutputSet set;
    set.stage((dir / "a.txt").string(), text("new"));
    EXPECT_THROW(set.stage((dir / "b.txt").string(),
                           [](const std::string&) { throw std::runtime_error("disk full"); }),
                 InputError);
  }
  std::ifstream in(dir / "a.txt");
  std::string content;
  in >> content;
  EXPECT_EQ(content, "previous");  // the earlier output of the set was not published
  EXPECT_EQ(fileCount(dir), 1u);
}

TEST(OutputSet, AnUncommittedSetRemovesItsTemporaries) {
  const auto dir = test::tempDir();
  {
    OutputSet set;
    set.stage((dir / "a.txt").string(), text("a"));
    EXPECT_EQ(fileCount(dir), 1u);  // the temporary
  }
  EXPECT_EQ(fileCount(dir), 0u);
}

TEST(OutputSet, ASignalWhileStagedRemovesTheTemporaries) {
  const auto dir = test::tempDir();
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    OutputSet set;
    set.stage((dir / "a.txt").string(), text("a"));
    ::raise(SIGTERM);
    _exit(0);  // not reached: the default action ends the process
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  EXPECT_EQ(fileCount(dir), 0u);
}

TEST(OutputSet, ADirectoryInTheWayFailsBeforeAnythingIsPublished) {
  const auto dir = test::tempDir();
  fs::create_directory(dir / "b.txt");
  OutputSet set;
  set.stage((dir / "a.txt").string(), text("a"));
  set.stage((dir / "b.txt").string(), text("b"));
  EXPECT_THROW(set.commit(), InputError);
  EXPECT_FALSE(fs::exists(dir / "a.txt"));
  EXPECT_EQ(fileCount(dir), 0u);
  EXPECT_THROW(checkOutputPath((dir / "b.txt").string(), "--output", {}), InputError);
}

}  // namespace
}  // namespace lvox
