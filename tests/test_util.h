#pragma once
// Helpers shared by the tests: a fresh temporary directory per test and file writing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace lvox::test {

// A new empty directory under the build's test area, named after the running test.
inline std::filesystem::path tempDir() {
  const char* base = std::getenv("LVOX_TEST_TMP");
  const testing::TestInfo* info = testing::UnitTest::GetInstance()->current_test_info();
  std::filesystem::path dir = std::filesystem::path(base ? base : "/tmp/lvox-tests") /
                              (std::string(info->test_suite_name()) + "." + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline void writeFile(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

}  // namespace lvox::test
