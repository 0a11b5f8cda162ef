// The length check of volume/media/vdb_precheck.h: real files pass it, and files whose
// lengths made OpenVDB allocate gigabytes (found by fuzzing) are refused, fast.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "src/core/error.h"
#include "test_util.h"
#include "volume/media/vdb_precheck.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string error(const fs::path& p) {
  try {
    precheckVdbFile(p.string(), "media[0].file");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(VdbPrecheck, RealFilesPass) {
  EXPECT_EQ(error(fs::path(LVOX_SOURCE_DIR) / "assets/smoke_plume.vdb"), "");
  EXPECT_EQ(error(fs::path(LVOX_SOURCE_DIR) / "tests/fuzz/seeds/vdb/density_small.vdb"), "");
  const fs::path shared = fs::path(LVOX_SHARED_DIR) / "assets/vdb";
  if (!fs::exists(shared)) GTEST_SKIP() << "shared assets absent";
  for (const char* name : {"smoke.vdb", "blender_smoke_plume.vdb", "wdas_cloud_sixteenth.vdb"})
    EXPECT_EQ(error(shared / name), "") << name;
}

// The seed with the length of its grid's name (the first string after the file's metadata
// and the grid count) set to 4 GiB - 1.
TEST(VdbPrecheck, HugeStringLengthIsRefused) {
  std::string bytes = readAll(fs::path(LVOX_SOURCE_DIR) / "tests/fuzz/seeds/vdb/density_small.vdb");
  const size_t name = bytes.find("density");
  ASSERT_NE(name, std::string::npos);
  const uint32_t huge = 0xFFFFFFFFu;
  std::memcpy(&bytes[name - 4], &huge, 4);
  const auto dir = test::tempDir();
  test::writeFile(dir / "huge.vdb", bytes);
  const std::string msg = error(dir / "huge.vdb");
  EXPECT_NE(msg.find("of 4294967295 bytes in"), std::string::npos) << msg;
}

// OpenVDB 10 goes on reading a file whose format version is corrupt (0 here): refused.
TEST(VdbPrecheck, OldOrCorruptVersionIsRefused) {
  std::string bytes = readAll(fs::path(LVOX_SOURCE_DIR) / "tests/fuzz/seeds/vdb/density_small.vdb");
  const uint32_t zero = 0;
  std::memcpy(&bytes[8], &zero, 4);
  const auto dir = test::tempDir();
  test::writeFile(dir / "old.vdb", bytes);
  EXPECT_NE(error(dir / "old.vdb").find("version 0 is older than 221"), std::string::npos);
}

TEST(VdbPrecheck, EveryTruncationIsRefusedOrLeftToOpenVdb) {
  // Cuts inside the part walked here are refused; later cuts pass (OpenVDB then fails on
  // the tree data, as Media.TruncatedAndCorruptRealVdb checks).
  const std::string bytes =
      readAll(fs::path(LVOX_SOURCE_DIR) / "tests/fuzz/seeds/vdb/density_small.vdb");
  const auto dir = test::tempDir();
  int refused = 0;
  for (size_t cut = 0; cut < 200; ++cut) {
    test::writeFile(dir / "cut.vdb", bytes.substr(0, cut));
    refused += error(dir / "cut.vdb") != "";
  }
  EXPECT_EQ(refused, 200);
}

}  // namespace
}  // namespace lvox
