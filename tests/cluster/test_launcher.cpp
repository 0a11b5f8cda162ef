// How lvox tells that an MPI launcher started it, and what a build without MPI does then.
#include <gtest/gtest.h>

#include <cstdlib>

#include "src/cluster/launcher.h"
#include "src/cluster/process_group.h"

namespace lvox {
namespace {

// Sets the launcher variables for one test and clears them after.
class LauncherEnvironment : public testing::Test {
 protected:
  static constexpr const char* kVariables[] = {"OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE",
                                               "PMI_RANK", "PMI_SIZE", "PMIX_RANK"};
  void SetUp() override { clear(); }
  void TearDown() override { clear(); }
  static void clear() {
    for (const char* v : kVariables) unsetenv(v);
  }
};

TEST_F(LauncherEnvironment, NoLauncher) { EXPECT_FALSE(launchedRank().has_value()); }

TEST_F(LauncherEnvironment, OpenMpiRankAndSize) {
  setenv("OMPI_COMM_WORLD_RANK", "1", 1);
  setenv("OMPI_COMM_WORLD_SIZE", "4", 1);
  const auto launched = launchedRank();
  ASSERT_TRUE(launched.has_value());
  EXPECT_EQ(launched->rank, 1);
  EXPECT_EQ(launched->size, 4);
  EXPECT_EQ(launched->variable, "OMPI_COMM_WORLD_RANK");
  EXPECT_TRUE(launchedWithOthers(*launched));
}

TEST_F(LauncherEnvironment, SingleRankJobIsAlone) {
  setenv("PMI_RANK", "0", 1);
  setenv("PMI_SIZE", "1", 1);
  const auto launched = launchedRank();
  ASSERT_TRUE(launched.has_value());
  EXPECT_FALSE(launchedWithOthers(*launched));
}

TEST_F(LauncherEnvironment, PmixGivesOnlyTheRank) {
  setenv("PMIX_RANK", "0", 1);
  const auto launched = launchedRank();
  ASSERT_TRUE(launched.has_value());
  EXPECT_FALSE(launched->size.has_value());
  EXPECT_FALSE(launchedWithOthers(*launched));
  setenv("PMIX_RANK", "3", 1);
  EXPECT_TRUE(launchedWithOthers(*launchedRank()));
}

TEST_F(LauncherEnvironment, GarbageIsNoLauncher) {
  setenv("OMPI_COMM_WORLD_RANK", "one", 1);
  EXPECT_FALSE(launchedRank().has_value());
}

// Built without MPI, a process a launcher started as one of several refuses to run (every
// rank would render the whole image and write the same files), naming the variable.
TEST_F(LauncherEnvironment, BuildWithoutMpiRefusesSeveralRanks) {
  if (ProcessGroup::mpiBuilt())
    GTEST_SKIP() << "this build has MPI: joining would start MPI (tests/app/test_mpi_cli.cpp "
                    "runs lvox under mpirun instead)";
  setenv("OMPI_COMM_WORLD_RANK", "1", 1);
  setenv("OMPI_COMM_WORLD_SIZE", "2", 1);
  int argc = 0;
  char** argv = nullptr;
  try {
    ProcessGroup::join(argc, argv);
    ADD_FAILURE() << "joined";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("rank 1 of 2 (OMPI_COMM_WORLD_RANK)"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("built without MPI"), std::string::npos) << e.what();
  }
  clear();
  const auto alone = ProcessGroup::join(argc, argv);
  EXPECT_EQ(alone->collective().size(), 1);
}

// The one-process collective: sums are the values, the counter counts.
TEST(SingleProcess, IsTrivial) {
  SingleProcess one;
  std::vector<float> v{1.5f, -2.0f};
  one.sum(std::span<float>(v));
  EXPECT_EQ(v, (std::vector<float>{1.5f, -2.0f}));
  one.resetCounter();
  EXPECT_EQ(one.take(3), 0u);
  EXPECT_EQ(one.take(1), 3u);
  one.resetCounter();
  EXPECT_EQ(one.take(1), 0u);
  EXPECT_EQ(one.gather("abc", 0), std::vector<std::string>{"abc"});
}

}  // namespace
}  // namespace lvox
