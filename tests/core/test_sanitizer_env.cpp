// The sanitizer build (LVOX_SANITIZE=ON, .ci/sanitize) must run its tests with the options
// of cmake/instrumentation.cmake: ctest's ENVIRONMENT carries them, through an escaping
// that tests/CMakeLists.txt explains and that this test guards.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

namespace {

#if defined(__SANITIZE_ADDRESS__)
TEST(SanitizerBuild, CtestGivesTheOptions) {
  for (const char* name : {"ASAN_OPTIONS", "LSAN_OPTIONS", "UBSAN_OPTIONS", "LVOX_TEST_TMP"}) {
    const char* value = std::getenv(name);
    ASSERT_NE(value, nullptr) << name;
    // One variable each: no other variable swallowed into this one.
    EXPECT_EQ(std::string(value).find(';'), std::string::npos) << name << "=" << value;
  }
  EXPECT_NE(std::string(std::getenv("LSAN_OPTIONS")).find(".ci/lsan.supp"), std::string::npos);
}
#endif

}  // namespace
