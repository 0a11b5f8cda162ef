// EXR files whose headers made OpenEXR allocate gigabytes (found by fuzzing) are refused
// fast by src/core/exr_precheck.h, and readExr still reads large images exactly (it now
// decodes them a strip of rows at a time).
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "src/core/error.h"
#include "src/core/image_io.h"
#include "test_util.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string readError(const fs::path& p) {
  try {
    readExr(p.string());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const fs::path kSeed = fs::path(LVOX_SOURCE_DIR) / "tests/fuzz/seeds/exr/rgb_float.exr";

TEST(ExrPrecheck, HugeAttributeSizeIsRefused) {
  std::string bytes = readAll(kSeed);
  const std::string key("lvox.spp\0string\0", 16);
  const size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  const int32_t huge = 0x7fffffff;
  std::memcpy(&bytes[at + key.size()], &huge, 4);
  const auto dir = test::tempDir();
  test::writeFile(dir / "huge.exr", bytes);
  EXPECT_NE(readError(dir / "huge.exr").find("claims 2147483647 bytes"), std::string::npos);
}

// OpenEXR reads a channel list to its empty name, and fixed-size values by their type,
// whatever size the file declares for them (found by fuzzing): a channel list declared one
// byte short put the precheck on the list's terminator, read as the header's end, while
// OpenEXR read on to a string attribute of 1.8 GB. The precheck now walks the header as
// OpenEXR does; and readAnyImage sends an EXR to readExr by its magic number, whatever its
// name, since OpenImageIO would pass it to OpenEXR unchecked.
TEST(ExrPrecheck, HeaderIsWalkedAsOpenExrReadsIt) {
  std::string bytes = readAll(kSeed);
  const std::string channels("channels\0chlist\0", 16);
  const size_t at = bytes.find(channels);
  ASSERT_NE(at, std::string::npos);
  int32_t size = 0;
  std::memcpy(&size, &bytes[at + channels.size()], 4);
  size -= 1;  // the list's own terminator is left out
  std::memcpy(&bytes[at + channels.size()], &size, 4);
  const std::string spp("lvox.spp\0string\0", 16);
  const size_t sppAt = bytes.find(spp);
  ASSERT_NE(sppAt, std::string::npos);
  const int32_t huge = 0x7fffffff;
  std::memcpy(&bytes[sppAt + spp.size()], &huge, 4);
  const auto dir = test::tempDir();
  test::writeFile(dir / "lying.exr", bytes);
  EXPECT_NE(readError(dir / "lying.exr").find("attribute 'lvox.spp' claims 2147483647 bytes"),
            std::string::npos)
      << readError(dir / "lying.exr");
  test::writeFile(dir / "lying.png", bytes);
  try {
    readAnyImage((dir / "lying.png").string());
    FAIL() << "read a lying EXR named .png";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("claims 2147483647 bytes"), std::string::npos) << e.what();
  }
  // The untouched seed still reads: the walk agrees with OpenEXR on a valid header.
  EXPECT_EQ(readExr(kSeed.string()).width, readAnyImage(kSeed.string()).width);
}

TEST(ExrPrecheck, MoreRowsThanOffsetsCanFitAreRefused) {
  std::string bytes = readAll(kSeed);
  const std::string key("dataWindow\0box2i\0", 17);
  const size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  const int32_t yMax = 1 << 28;  // xMin, yMin, xMax, yMax follow the size
  std::memcpy(&bytes[at + key.size() + 4 + 12], &yMax, 4);
  const auto dir = test::tempDir();
  test::writeFile(dir / "tall.exr", bytes);
  EXPECT_NE(readError(dir / "tall.exr").find("a data window of 268435457 rows"), std::string::npos)
      << readError(dir / "tall.exr");
}

TEST(ExrPrecheck, LargeImagesReadExactlyStripByStrip) {
  // 2048 x 600 pixels: three strips of 512 rows (2^20 pixels) and a shorter one.
  Image image(2048, 600);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    const auto v = static_cast<float>(i % 9973) * 0.25f;
    image.pixels[i] = RGB(v, v + 1.0f, v + 2.0f);
  }
  const auto dir = test::tempDir();
  writeExr((dir / "big.exr").string(), image);
  const Image back = readExr((dir / "big.exr").string());
  ASSERT_EQ(back.width, 2048);
  ASSERT_EQ(back.height, 600);
  ASSERT_EQ(back.pixels.size(), image.pixels.size());
  size_t differ = 0;
  for (size_t i = 0; i < image.pixels.size(); ++i) differ += !(back.pixels[i] == image.pixels[i]);
  EXPECT_EQ(differ, 0u);
}

}  // namespace
}  // namespace lvox
