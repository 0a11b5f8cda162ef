#include <gtest/gtest.h>

#include <cmath>

#include "src/core/error.h"
#include "src/core/image_metrics.h"

namespace lvox {
namespace {

TEST(ImageMetrics, KnownValues) {
  Image reference(2, 1, RGB(1.0f)), test(2, 1, RGB(1.0f));
  // Pixel 0 off by +0.6 in red only: sum|A-B| = 0.6 over sum|B| = 6 -> 10 %.
  test.at(0, 0).x = 1.6f;
  const ImageError e = compareImages(test, reference);
  EXPECT_NEAR(e.deltaPercent, 10.0, 1e-5);
  EXPECT_NEAR(e.rmse, std::sqrt(0.36 / 6.0), 1e-6);
  EXPECT_NEAR(e.relMse, 0.36 / 1.01 / 6.0, 1e-6);
  EXPECT_NEAR(e.psnrDb, 10.0 * std::log10(1.0 / (0.36 / 6.0)), 1e-4);
  EXPECT_NEAR(e.maxAbs, 0.6, 1e-6);
  EXPECT_NEAR(e.meanRatio, 6.6 / 6.0, 1e-6);
}

TEST(ImageMetrics, IdenticalImages) {
  const Image a(3, 3, RGB(0.25f));
  const ImageError e = compareImages(a, a);
  EXPECT_EQ(e.deltaPercent, 0.0);
  EXPECT_EQ(e.rmse, 0.0);
  EXPECT_TRUE(std::isinf(e.psnrDb));
}

TEST(ImageMetrics, ANonFiniteImageHasNoError) {
  Image reference(2, 2, RGB(1.0f));
  reference.pixels[3] = RGB(std::nanf(""));
  EXPECT_THROW(compareImages(Image(2, 2, RGB(1.0f)), reference, "a.exr", "ref.exr"), InputError);
  EXPECT_THROW(compareImages(reference, Image(2, 2, RGB(1.0f)), "a.exr", "ref.exr"), InputError);
}

TEST(ImageMetrics, SizeMismatchNamesTheFiles) {
  try {
    compareImages(Image(2, 2), Image(3, 2), "a.exr", "b.exr");
    FAIL();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("a.exr"), std::string::npos);
    EXPECT_NE(msg.find("b.exr"), std::string::npos);
  }
}

}  // namespace
}  // namespace lvox
