#include <gtest/gtest.h>
#include <png.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include "src/core/atomic_file.h"
#include "src/core/error.h"
#include "src/core/image_io.h"
#include "test_util.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

Image gradient(int w, int h) {
  Image image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      image.at(x, y) = RGB(0.1f * static_cast<float>(x), 1e-3f * static_cast<float>(y), 123.456f);
  return image;
}

bool onlyFiles(const fs::path& dir, std::vector<std::string> expected) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  std::sort(expected.begin(), expected.end());
  return names == expected;
}

TEST(ImageIo, ExrFloatRoundTripIsExact) {
  const auto dir = test::tempDir();
  const Image image = gradient(7, 5);
  writeExr((dir / "a.exr").string(), image, false, {{"lvox.spp", "64"}});
  ImageMetadata meta;
  const Image back = readExr((dir / "a.exr").string(), &meta);
  ASSERT_EQ(back.width, 7);
  ASSERT_EQ(back.height, 5);
  for (size_t i = 0; i < image.pixels.size(); ++i) EXPECT_EQ(back.pixels[i], image.pixels[i]);
  EXPECT_EQ(meta["lvox.spp"], "64");
  EXPECT_TRUE(onlyFiles(dir, {"a.exr"}));
}

TEST(ImageIo, ExrHalfClampsAndCounts) {
  const auto dir = test::tempDir();
  Image image = gradient(4, 4);
  image.at(1, 1) = RGB(1e6f, 70000.0f, 1.0f);
  const ExrWriteStats stats = writeExr((dir / "h.exr").string(), image, true);
  EXPECT_EQ(stats.clamped, 2u);
  const Image back = readExr((dir / "h.exr").string());
  EXPECT_EQ(back.at(1, 1).x, 65504.0f);
  // Half has 11 significant bits: relative error <= 2^-11.
  EXPECT_NEAR(back.at(3, 2).x, 0.3f, 0.3f * 4.9e-4f);
  EXPECT_NEAR(back.at(0, 0).z, 123.456f, 123.456f * 4.9e-4f);
}

TEST(ImageIo, NonFiniteAndNegativeValuesNeverReachTheFile) {
  const auto dir = test::tempDir();
  Image image(2, 2, RGB(1.0f));
  image.at(0, 0) = RGB(std::numeric_limits<float>::quiet_NaN(), -1.0f, 0.5f);
  image.at(1, 1) = RGB(std::numeric_limits<float>::infinity(), 2.0f, 3.0f);
  const ExrWriteStats stats = writeExr((dir / "n.exr").string(), image);
  EXPECT_EQ(stats.sanitized, 3u);
  const Image back = readExr((dir / "n.exr").string());
  EXPECT_EQ(back.at(0, 0), RGB(0.0f, 0.0f, 0.5f));
  EXPECT_EQ(back.at(1, 1), RGB(0.0f, 2.0f, 3.0f));
}

TEST(ImageIo, CorruptAndTruncatedExrAreErrors) {
  const auto dir = test::tempDir();
  writeExr((dir / "good.exr").string(), gradient(32, 32));
  std::ifstream in(dir / "good.exr", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (size_t k : {1u, 4u, 8u, 12u, 15u}) {
    test::writeFile(dir / "cut.exr", bytes.substr(0, bytes.size() * k / 16));
    EXPECT_THROW(readExr((dir / "cut.exr").string()), InputError) << k << "/16";
  }
  test::writeFile(dir / "junk.exr", "this is not an image at all");
  try {
    readExr((dir / "junk.exr").string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("junk.exr"), std::string::npos);
  }
  EXPECT_THROW(readExr((dir / "missing.exr").string()), InputError);
}

TEST(ImageIo, PngPreviewUsesTheDocumentedToneMap) {
  const auto dir = test::tempDir();
  Image image(3, 2, RGB(0.0f));
  image.at(0, 0) = RGB(1.0f, 0.1f, 100.0f);
  writePng((dir / "p.png").string(), image);
  png_image png;
  std::memset(&png, 0, sizeof(png));
  png.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&png, (dir / "p.png").c_str()));
  png.format = PNG_FORMAT_RGB;
  std::vector<uint8_t> buffer(PNG_IMAGE_SIZE(png));
  ASSERT_TRUE(png_image_finish_read(&png, nullptr, buffer.data(), 0, nullptr));
  EXPECT_EQ(png.width, 3u);
  EXPECT_EQ(png.height, 2u);
  // 1 - exp(-1) = 0.632 -> sRGB 0.8138 -> 208; 1 - exp(-0.1) = 0.0952 -> 0.3418 -> 87.
  EXPECT_EQ(buffer[0], 208);
  EXPECT_EQ(buffer[1], 87);
  EXPECT_EQ(buffer[2], 255);
  EXPECT_EQ(buffer[3], 0);
}

TEST(AtomicFile, FailureMidWriteKeepsThePreviousFile) {
  const auto dir = test::tempDir();
  const std::string path = (dir / "out.txt").string();
  test::writeFile(path, "previous");
  EXPECT_THROW(publishAtomically(path,
                                 [](const std::string& tmp) {
                                   std::ofstream(tmp) << "half of the new content";
                                   throw std::runtime_error("injected failure");
                                 }),
               InputError);
  std::ifstream in(path);
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "previous");
  EXPECT_TRUE(onlyFiles(dir, {"out.txt"}));  // no temporary left behind
}

TEST(AtomicFile, VerificationFailureKeepsThePreviousFile) {
  const auto dir = test::tempDir();
  const std::string path = (dir / "out.exr").string();
  writeExr(path, gradient(4, 4));
  EXPECT_THROW(publishAtomically(
                   path, [](const std::string& tmp) { std::ofstream(tmp) << "garbage"; },
                   [](const std::string& tmp) { readExr(tmp); }),
               InputError);
  EXPECT_EQ(readExr(path).width, 4);
  EXPECT_TRUE(onlyFiles(dir, {"out.exr"}));
}

TEST(AtomicFile, OutputPathChecks) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "in.json", "{}");
  EXPECT_THROW(checkOutputPath((dir / "nodir" / "x.exr").string(), "--output", {}), InputError);
  EXPECT_THROW(
      checkOutputPath((dir / "in.json").string(), "--output", {(dir / "in.json").string()}),
      InputError);
  EXPECT_THROW(
      checkOutputPath((dir / "." / "in.json").string(), "--output", {(dir / "in.json").string()}),
      InputError);
  EXPECT_NO_THROW(
      checkOutputPath((dir / "x.exr").string(), "--output", {(dir / "in.json").string()}));
}

TEST(AtomicFile, UnwritableDestinationIsAnError) {
  if (getuid() == 0) {
    // Root ignores directory permissions; a full device still refuses the rename target.
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "/dev/full missing";
  }
  // /dev is not a place a temporary file can be renamed onto a device: error, no crash.
  EXPECT_THROW(writeExr("/proc/lvox-cannot-exist/out.exr", gradient(2, 2)), InputError);
}

}  // namespace
}  // namespace lvox
