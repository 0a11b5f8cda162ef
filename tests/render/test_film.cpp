// The film's layer sums (src/render/film.h): means per pixel, depth over the samples that
// hit a surface, and the variance of the mean s^2 / n from the samples' moments.
#include <gtest/gtest.h>

#include "src/render/film.h"

namespace lvox {
namespace {

const std::vector<float>& values(const std::vector<ExtraChannel>& channels,
                                 const std::string& name) {
  for (const ExtraChannel& c : channels)
    if (c.name == name) return c.values;
  throw std::runtime_error("no channel " + name);
}

TEST(Film, LayerMeansDepthOverHitsAndVarianceOfTheMean) {
  Film film(2, 1, LayerSet::parse("direct,normal,depth,variance", true, "test"));
  ASSERT_TRUE(film.hasLayers());
  PixelLayerSums sums{};
  // Four samples of pixel (1, 0): radiance 1, 2, 3, 4 (red); two hit a surface at 2 and 4.
  for (int i = 1; i <= 4; ++i) {
    SampleLayers s;
    s.direct = RGB(static_cast<float>(i), 0.0f, 0.5f);
    s.hit = i % 2 == 0;
    s.depth = s.hit ? static_cast<float>(i) : 0.0f;
    s.normal = s.hit ? Vec3(0.0f, 1.0f, 0.0f) : Vec3(0.0f);
    const RGB radiance = s.direct;
    film.beauty.at(1, 0) += radiance;
    film.addSample(sums, radiance, s);
  }
  film.addPixel(1, 0, sums);
  const std::vector<ExtraChannel> channels = film.layerChannels(4);
  EXPECT_FLOAT_EQ(values(channels, "direct.R")[1], 2.5f);
  EXPECT_FLOAT_EQ(values(channels, "direct.B")[1], 0.5f);
  EXPECT_FLOAT_EQ(values(channels, "normal.Y")[1], 0.5f);  // the mean, not renormalised
  EXPECT_FLOAT_EQ(values(channels, "depth.Z")[1], 3.0f);
  EXPECT_FLOAT_EQ(values(channels, "coverage.Y")[1], 0.5f);
  // s^2 of 1, 2, 3, 4 is 5/3; the variance of their mean 5/12. A constant channel has none.
  EXPECT_NEAR(values(channels, "variance.R")[1], 5.0 / 12.0, 1e-7);
  EXPECT_EQ(values(channels, "variance.B")[1], 0.0f);
  // The untouched pixel: zero everywhere, no hit.
  EXPECT_EQ(values(channels, "depth.Z")[0], 0.0f);
  EXPECT_EQ(values(channels, "coverage.Y")[0], 0.0f);
  EXPECT_EQ(channels.size(), 3u + 3u + 2u + 3u);
}

// A bright pixel with little noise: sums of squares in float would cancel to nothing (or
// below zero); the film's double sums keep the variance.
TEST(Film, VarianceSurvivesALargeMean) {
  Film film(1, 1, LayerSet::parse("variance", true, "test"));
  PixelLayerSums sums{};
  const int n = 4096;
  for (int i = 0; i < n; ++i) {
    const float v = 1000.0f + (i % 2 == 0 ? 0.01f : -0.01f);
    film.beauty.at(0, 0) += RGB(v);
    film.addSample(sums, RGB(v), SampleLayers{});
  }
  film.addPixel(0, 0, sums);
  const double s2 = 0.01 * 0.01 * n / (n - 1.0);  // the samples' variance, about 1e-4
  const float got = values(film.layerChannels(n), "variance.G")[0];
  // 1000 +- 0.01 is not exact in float (spacing 6e-5): 1 % is what the inputs allow.
  EXPECT_NEAR(got, s2 / n, 0.01 * s2 / n);
}

TEST(Film, LayerBytesPerPixel) {
  EXPECT_EQ(Film::layerBytesPerPixel({}), 0u);
  EXPECT_EQ(Film::layerBytesPerPixel(LayerSet::parse("all", true, "t")), kMaxLayerSlots * 8u);
  EXPECT_EQ(Film::layerBytesPerPixel(LayerSet::parse("depth", true, "t")), 16u);
}

}  // namespace
}  // namespace lvox
