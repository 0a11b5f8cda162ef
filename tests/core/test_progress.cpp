// The progress line (src/core/progress.h) with a fake clock: what it shows per phase, that
// the share never goes back, that nested phases give the line back, and that it is silent
// when disabled.
#include <gtest/gtest.h>

#include <regex>
#include <thread>

#include "src/core/progress.h"

namespace lvox {
namespace {

struct FakeTerminal {
  double now = 0.0;
  std::vector<std::string> writes;
  Progress progress{Progress::Output{[this](const std::string& t) { writes.push_back(t); },
                                     [this] { return now; }}};
};

TEST(Progress, PhasesShowElapsedShareAndTimeLeft) {
  FakeTerminal t;
  t.progress.enable(true);
  t.progress.beginPhase("octree_build");
  t.now = 1.0;
  EXPECT_EQ(t.progress.line(), "octree_build  1.0 s");  // no known work: elapsed only
  t.progress.endPhase();
  EXPECT_EQ(t.writes.back(), "\r\033[K");  // the last phase clears the line
  t.progress.beginPhase("render");
  t.progress.addWork(100);
  EXPECT_EQ(t.progress.line(), "render    0%  0.0 s");
  t.now = 3.0;
  t.progress.advance(25);
  // A quarter in 2 s: three quarters left take 6 s.
  EXPECT_EQ(t.progress.line(), "render   25%  2.0 s, about 6.0 s left");
  EXPECT_EQ(t.writes.back(), "\rlvox: render   25%  2.0 s, about 6.0 s left\033[K");
}

// Work counted outside every phase (a tile loop run by a tool without PhaseTimer) prints
// nothing, not an empty "lvox:" line.
TEST(Progress, WorkOutsideAnyPhasePrintsNothing) {
  FakeTerminal t;
  t.progress.enable(true);
  t.now = 5.0;
  t.progress.advance(10);
  EXPECT_TRUE(t.writes.empty());
  EXPECT_EQ(t.progress.line(), "");
}

TEST(Progress, ShareNeverGoesBackAndNestedPhasesGiveTheLineBack) {
  FakeTerminal t;
  t.progress.enable(true);
  t.progress.beginPhase("interreflection");
  t.progress.addWork(10);
  t.progress.advance(5);
  EXPECT_NE(t.progress.line().find(" 50%"), std::string::npos);
  t.progress.addWork(10);  // more work found: 5 of 20, but 50 % was shown
  EXPECT_NE(t.progress.line().find(" 50%"), std::string::npos) << t.progress.line();
  t.progress.beginPhase("cloud_exchange");
  EXPECT_EQ(t.progress.line(), "cloud_exchange  0.0 s");
  t.progress.endPhase();
  t.progress.advance(15);
  EXPECT_NE(t.progress.line().find("100%"), std::string::npos) << t.progress.line();
}

TEST(Progress, ManyThreadsPrintAMonotoneShare) {
  FakeTerminal t;
  t.progress.enable(true);
  t.progress.beginPhase("render");
  t.progress.addWork(4000);
  std::vector<std::thread> threads;
  for (int k = 0; k < 4; ++k)
    threads.emplace_back([&] {
      for (int i = 0; i < 1000; ++i) t.progress.advance(1);
    });
  for (std::thread& th : threads) th.join();
  t.now = 10.0;  // past the print interval: the next advance prints
  t.progress.advance(0);
  const std::regex percent(R"(render\s+(\d+)%)");
  int last = -1;
  for (const std::string& w : t.writes) {
    std::smatch m;
    if (!std::regex_search(w, m, percent)) continue;
    const int p = std::stoi(m[1]);
    EXPECT_GE(p, last) << w;
    last = p;
  }
  EXPECT_EQ(last, 100);
}

TEST(Progress, DisabledWritesNothing) {
  FakeTerminal t;
  t.progress.beginPhase("render");
  t.progress.addWork(10);
  t.progress.advance(10);
  t.progress.endPhase();
  EXPECT_TRUE(t.writes.empty());
}

}  // namespace
}  // namespace lvox
