#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

#include "src/core/error.h"
#include "src/core/work_budget.h"

namespace lvox {
namespace {

std::string errorOf(const WorkBudget& w) {
  try {
    w.throwIfExhausted();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(WorkBudget, ParsesCountsAndAuto) {
  EXPECT_EQ(parseEvaluationCount("auto", "f", "k"), 0u);
  EXPECT_EQ(parseEvaluationCount("5e10", "f", "k"), 50000000000u);
  EXPECT_EQ(parseEvaluationCount("1000000", "f", "k"), 1000000u);
  for (const char* bad : {"", "x", "1e5", "-1e9", "nan", "inf", "1e19", "5e10 ", "2G"})
    EXPECT_THROW(parseEvaluationCount(bad, "f", "k"), InputError) << bad;
  try {
    parseEvaluationCount("1e5", "scene.json", "render.max_evaluations");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "scene.json: render.max_evaluations: \"1e5\": must be within [1e6, 1e18]");
  }
}

// 0 derives the limit from the camera samples, with a floor for tiny images.
TEST(WorkBudget, TheDefaultScalesWithTheCameraSamples) {
  EXPECT_EQ(WorkBudget(0, 1, "s").limit(), static_cast<uint64_t>(WorkBudget::kFloor));
  EXPECT_EQ(WorkBudget(0, 512 * 512 * 4, "s").limit(),
            static_cast<uint64_t>(WorkBudget::kPerCameraSample * 512 * 512 * 4));
  EXPECT_EQ(WorkBudget(12345678, 512 * 512 * 4, "s").limit(), 12345678u);
}

TEST(WorkBudget, ChargesPastTheLimitExhaustIt) {
  WorkBudget w(1000000, 1, "scene.json");
  w.charge(600000, "the cache");
  EXPECT_FALSE(w.exhausted());
  EXPECT_NO_THROW(w.throwIfExhausted());
  w.charge(400000, "the cache");  // exactly the limit is allowed
  EXPECT_FALSE(w.exhausted());
  w.charge(1, "the cache");
  EXPECT_TRUE(w.exhausted());
  EXPECT_EQ(errorOf(w),
            "scene.json: render.max_evaluations: the cache needed 1e+06 medium evaluations, past "
            "the budget of 1e+06; raise it with --max-evaluations or render.max_evaluations, or "
            "lower the resolution, spp, tolerance or the media's density");
}

// A phase is projected from its first samples: 5 % of the samples having cost 1e5
// evaluations project 2e6 (plus the 1e5 charged before), past a budget of 1.5e6.
TEST(WorkBudget, ACameraPhaseIsStoppedByItsProjection) {
  WorkBudget w(1500000, 1, "scene.json");
  w.charge(100000, "the cache");
  w.project(100000, 5, 100, "the camera rays");
  EXPECT_TRUE(w.exhausted());
  EXPECT_NE(errorOf(w).find("the camera rays would need about 2.1e+06 medium evaluations "
                            "(projected after 5 % of them), past the budget of 1.5e+06"),
            std::string::npos)
      << errorOf(w);
  // Under the limit when projected: nothing happens.
  WorkBudget fits(3000000, 1, "scene.json");
  fits.project(100000, 5, 100, "the camera rays");
  EXPECT_FALSE(fits.exhausted());
}

// Before kProbeFraction of the samples are done there is nothing to project from: only
// what was spent counts (one costly first sample is not extrapolated, but spending past
// the limit stops the phase at once).
TEST(WorkBudget, FewSamplesAreNotExtrapolated) {
  WorkBudget w(1000000, 1, "scene.json");
  w.project(900000, 1, 1000, "the camera rays");
  EXPECT_FALSE(w.exhausted());
  w.project(1000001, 2, 1000, "the camera rays");
  EXPECT_TRUE(w.exhausted());
  EXPECT_NE(errorOf(w).find("the camera rays needed 1e+06"), std::string::npos) << errorOf(w);
}

// Threads racing past the limit: exhausted once, with one well-formed message.
TEST(WorkBudget, ConcurrentChargesReportOnce) {
  WorkBudget w(1000000, 1, "scene.json");
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&] {
      for (int i = 0; i < 1000; ++i) w.charge(1000, "the cache");
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(w.spent(), 4000000u);
  EXPECT_TRUE(w.exhausted());
  EXPECT_EQ(errorOf(w).rfind("scene.json: render.max_evaluations: the cache needed ", 0), 0u);
}

}  // namespace
}  // namespace lvox
