#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "src/core/check.h"

namespace lvox {
namespace {

TEST(Check, ABrokenInvariantThrowsNamingTheConditionAndPlace) {
  try {
    const int slots = 3;
    LVOX_CHECK(slots < 2, "too many slots");
    FAIL() << "no throw";
  } catch (const std::logic_error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("internal error: ", 0), 0u) << msg;
    EXPECT_NE(msg.find("test_check.cpp"), std::string::npos) << msg;
    EXPECT_NE(msg.find("slots < 2 (too many slots)"), std::string::npos) << msg;
  }
  EXPECT_NO_THROW(LVOX_CHECK(1 < 2, "fine"));
}

TEST(Check, DebugChecksOnlyInDebugBuilds) {
  int evaluated = 0;
  auto broken = [&] {
    ++evaluated;
    return false;
  };
#ifdef NDEBUG
  EXPECT_NO_THROW(LVOX_DCHECK(broken(), "hot path"));
  EXPECT_EQ(evaluated, 0);  // not even evaluated in release builds
#else
  EXPECT_THROW(LVOX_DCHECK(broken(), "hot path"), std::logic_error);
  EXPECT_EQ(evaluated, 1);
#endif
}

}  // namespace
}  // namespace lvox
