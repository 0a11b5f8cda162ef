#include <gtest/gtest.h>
#include <atomic>
#include <thread>
#include <vector>

#include "src/core/error.h"
#include "src/core/memory_budget.h"

namespace lvox {
namespace {

TEST(MemoryBudget, ParsesSizesInPowersOf1024) {
  EXPECT_EQ(parseByteSize("512M", "f", "k"), 512ull << 20);
  EXPECT_EQ(parseByteSize("4G", "f", "k"), 4ull << 30);
  EXPECT_EQ(parseByteSize("1.5G", "f", "k"), 3ull << 29);
  EXPECT_EQ(parseByteSize("2048k", "f", "k"), 2ull << 20);
  EXPECT_EQ(parseByteSize("1T", "f", "k"), 1ull << 40);
  EXPECT_EQ(parseByteSize("3000000", "f", "k"), 3000000u);
  for (const char* bad : {"", "G", "-1G", "4Q", "nanG", "1e400", "0.5M", "100", "1e19"})
    EXPECT_THROW(parseByteSize(bad, "f", "k"), InputError) << bad;
  try {
    parseByteSize("4Q", "scene.json", "render.max_memory");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "scene.json: render.max_memory: \"4Q\": unknown unit \"Q\" (k, M, G or T)");
  }
}

TEST(MemoryBudget, FormatsBytes) {
  EXPECT_EQ(formatBytes(512), "512 B");
  EXPECT_EQ(formatBytes(3ull << 29), "1.5 GB");
  EXPECT_EQ(formatBytes(256ull << 20), "256.0 MB");
}

TEST(MemoryBudget, ChecksAndReservesUpToTheLimitExactly) {
  MemoryBudget b(1000);
  b.check(1000, "f", "k", "x");  // fits exactly
  b.reserve(600, "f", "k", "x");
  EXPECT_EQ(b.reserved(), 600u);
  b.check(400, "f", "k", "x");
  EXPECT_THROW(b.check(401, "f", "k", "x"), InputError);
  EXPECT_THROW(b.reserve(401, "f", "k", "x"), InputError);
  EXPECT_EQ(b.reserved(), 600u);  // a refused reservation holds nothing
  EXPECT_THROW(b.check(~0ull, "f", "k", "x"), InputError);  // no overflow past the limit
  try {
    b.reserve(500, "scene.json", "pointcloud.target_surfels", "the point cloud");
    FAIL();
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("scene.json: pointcloud.target_surfels: the point cloud needs about 500 B", 0), 0u) << m;
    EXPECT_NE(m.find("budget of 1000 B (600 B already held)"), std::string::npos) << m;
    EXPECT_NE(m.find("--max-memory"), std::string::npos) << m;
  }
}

// tryReserve: for memory a render can do without (auto mixing's state) a refusal is an
// answer, not an error, and holds nothing.
TEST(MemoryBudget, TryReserveHoldsWhatFitsAndRefusesTheRest) {
  MemoryBudget b(1000);
  EXPECT_TRUE(b.tryReserve(600));
  EXPECT_EQ(b.reserved(), 600u);
  EXPECT_FALSE(b.tryReserve(401));
  EXPECT_EQ(b.reserved(), 600u);
  EXPECT_FALSE(b.tryReserve(~0ull));  // no overflow past the limit
  EXPECT_TRUE(b.tryReserve(400));     // fits exactly
  EXPECT_EQ(b.reserved(), 1000u);
  EXPECT_FALSE(b.tryReserve(1));
}

TEST(MemoryBudget, ConcurrentReservationsNeverPassTheLimit) {
  // 10,000 reservations of 1 kB from many threads against 5 MB: exactly 5,000 succeed
  // (the limit is a multiple of the size), whatever the interleaving.
  MemoryBudget b(5000 * 1024);
  std::atomic<int> granted{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t)
    threads.emplace_back([&] {
      for (int i = 0; i < 1250; ++i) {
        try {
          b.reserve(1024, "f", "k", "x");
          ++granted;
        } catch (const InputError&) {
        }
      }
    });
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(granted.load(), 5000);
  EXPECT_EQ(b.reserved(), 5000u * 1024u);
}

TEST(MemoryBudget, DefaultIsFourFifthsOfThePhysicalMemory) {
  EXPECT_EQ(MemoryBudget().limit(), physicalMemoryBytes() / 5 * 4);
  EXPECT_GT(physicalMemoryBytes(), 64ull << 20);
}

}  // namespace
}  // namespace lvox
