// Adaptive camera samples (src/render/adaptive_samples.h): the plan adds up to its budget
// within its bounds, follows the neighbours' variance as its cube root and never a
// pixel's own; renders keep their means (a uniform floor stays exact; a shadow edge's
// pixels are unbiased over seeds) and take less error than even samples at the same count.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>
#include <tuple>

#include "src/core/error.h"
#include "src/render/adaptive_samples.h"
#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"

namespace lvox {
namespace {

// Moments of `n` samples per pixel with the given sample variance (mean 1).
PixelMoments momentsOf(const std::vector<double>& variance, uint64_t n) {
  PixelMoments m(variance.size());
  for (size_t i = 0; i < variance.size(); ++i) {
    m.count[i] = n;
    m.sum[i] = static_cast<double>(n);
    m.squares[i] = static_cast<double>(n) + variance[i] * static_cast<double>(n - 1);
  }
  return m;
}

uint64_t total(const std::vector<uint32_t>& extra) {
  uint64_t t = 0;
  for (uint32_t e : extra) t += e;
  return t;
}

TEST(AdaptiveSamples, MomentsGiveTheSampleVariance) {
  PixelMoments m(1);
  for (double v : {1.0, 2.0, 4.0, 7.0}) {
    m.sum[0] += v;
    m.squares[0] += v * v;
    ++m.count[0];
  }
  // mean 3.5; sum of squared deviations 6.25 + 2.25 + 0.25 + 12.25 = 21; / 3
  EXPECT_NEAR(m.variance(0), 7.0, 1e-12);
  PixelMoments one(1);
  one.sum[0] = 3.0;
  one.squares[0] = 9.0;
  one.count[0] = 1;
  EXPECT_EQ(one.variance(0), 0.0);
}

TEST(AdaptiveSamples, AddUpToTheBudgetWithinTheBounds) {
  const int w = 37, h = 23, spp = 4, mean = 7;
  std::vector<double> variance(static_cast<size_t>(w) * h);
  uint64_t state = 12345;
  for (double& v : variance) {  // a few very noisy pixels among quiet ones
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    const double u = static_cast<double>(state >> 11) / 9007199254740992.0;
    v = u < 0.05 ? 1e4 * u : 1e-3 * u;
  }
  const std::vector<uint32_t> extra = adaptiveExtraSamples(momentsOf(variance, 4), w, h, spp, mean);
  ASSERT_EQ(extra.size(), variance.size());
  EXPECT_EQ(total(extra), static_cast<uint64_t>(mean - spp) * variance.size());
  // The pixels beside a noisy one take the samples: on average more than twice what the
  // others take (these get none beyond the first: their neighbours' deviation is 1e-4 of it).
  double beside = 0.0, apart = 0.0;
  int besideCount = 0, apartCount = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool noisy = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if ((dx != 0 || dy != 0) && nx >= 0 && ny >= 0 && nx < w && ny < h)
            noisy = noisy || variance[static_cast<size_t>(ny) * w + nx] > 1.0;
        }
      const size_t i = static_cast<size_t>(y) * w + x;
      EXPECT_LE(spp + extra[i], static_cast<uint32_t>(kMaxSamplesPerMean * mean));
      (noisy ? beside : apart) += spp + extra[i];
      ++(noisy ? besideCount : apartCount);
    }
  ASSERT_GT(besideCount, 0);
  ASSERT_GT(apartCount, 0);
  EXPECT_GT(beside / besideCount, 2.0 * apart / apartCount);
}

TEST(AdaptiveSamples, NoVarianceSpreadsTheSamplesEvenly) {
  const std::vector<uint32_t> extra =
      adaptiveExtraSamples(momentsOf(std::vector<double>(60, 0.0), 4), 10, 6, 4, 9);
  for (uint32_t e : extra) EXPECT_EQ(e, 5u);
}

// A pixel's count comes from its neighbours: a lone noisy pixel sends the samples to the
// 8 around it, and takes none beyond the first itself (nothing else varies).
TEST(AdaptiveSamples, APixelsOwnSamplesDoNotSetItsCount) {
  const int w = 9, h = 9;
  std::vector<double> variance(81, 0.0);
  variance[4 * 9 + 4] = 1.0;
  const std::vector<uint32_t> extra = adaptiveExtraSamples(momentsOf(variance, 4), w, h, 4, 5);
  EXPECT_EQ(extra[4 * 9 + 4], 0u);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if (dx != 0 || dy != 0) {
        EXPECT_GT(extra[(4 + dy) * 9 + 4 + dx], 5u);
      }
  EXPECT_EQ(total(extra), 81u);
}

// One noisy corner of a 20 x 20 image: its 3 neighbours could take all 800 extra samples
// but reach the cap (16 times the mean of 6, 96) first; the rest goes alike to the others.
TEST(AdaptiveSamples, WhatTheCappedPixelsCannotTakeGoesToTheOthers) {
  std::vector<double> variance(400, 0.0);
  variance[0] = 1.0;
  const std::vector<uint32_t> extra = adaptiveExtraSamples(momentsOf(variance, 4), 20, 20, 4, 6);
  EXPECT_EQ(total(extra), 800u);
  for (size_t i : {size_t(1), size_t(20), size_t(21)}) EXPECT_NEAR(extra[i], 92u, 1u) << i;
  for (size_t i = 0; i < extra.size(); ++i) {
    EXPECT_LE(4u + extra[i], 96u + 1u) << i;
    if (i != 1 && i != 20 && i != 21) {
      EXPECT_LE(extra[i], 2u) << i;
    }
  }
}

// Between two halves of variance 1 and 64, away from the border between them, the counts
// go as the cube root: 4 times as many samples where the deviation is 8 times as large.
TEST(AdaptiveSamples, CountsGoAsTheCubeRootOfTheVariance) {
  const int w = 40, h = 20;
  std::vector<double> variance(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) variance[static_cast<size_t>(y) * w + x] = x < w / 2 ? 1.0 : 64.0;
  const std::vector<uint32_t> extra = adaptiveExtraSamples(momentsOf(variance, 8), w, h, 1, 40);
  const double quiet = 1.0 + extra[10 * w + 5], noisy = 1.0 + extra[10 * w + 35];
  EXPECT_NEAR(noisy / quiet, 4.0, 0.1);
}

// A floor under a box, sunlit from the side: the box's silhouette and its shadow's edge
// are the only pixels whose samples differ (direct mode, a delta light).
std::string edgeScene(int spp, int adaptive, uint64_t seed) {
  std::ostringstream s;
  s << R"({"camera": {"position": [0, 6, 0.01], "look_at": [0, 0, 0], "up": [0, 0, -1], "vfov_deg": 50,
   "width": 32, "height": 32},
   "render": {"mode": "direct", "spp": )"
    << spp << R"(, "adaptive_spp": )" << adaptive << R"(, "seed": )" << seed << R"(},
   "materials": {"white": {"albedo": 0.8}},
   "shapes": [{"type": "quad", "corners": [[-9,0,-9],[9,0,-9],[9,0,9],[-9,0,9]], "material": "white"},
              {"type": "box", "min": [-0.9, 0, -0.7], "max": [0.6, 1.3, 0.8], "material": "white"}],
   "lights": [{"type": "directional", "direction": [0.6, -0.7, 0.2], "irradiance": 3}]})";
  return s.str();
}

RenderResult renderText(const std::string& text, Report* out = nullptr, int threads = 0) {
  Scene scene = parseScene(text, "/tmp/adaptive-test.json");
  scene.render.threads = threads;
  RenderPlan plan;
  plan.spp = scene.render.spp;
  Report report;
  RenderResult r = renderScene(scene.job(), plan, report);
  if (out) *out = report;
  return r;
}

double sumAbsDifference(const Image& a, const Image& b) {
  double d = 0.0;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) d += std::abs(static_cast<double>(a.pixels[i][c]) - b.pixels[i][c]);
  return d;
}

TEST(AdaptiveSamples, AUniformFloorStaysExact) {
  // Looking straight down at the lit floor only: every sample is rho E cos / pi.
  const std::string text =
      R"({"camera": {"position": [0, 3, 0], "look_at": [0, 0, 0], "up": [0, 0, -1],
   "vfov_deg": 10, "width": 6, "height": 5}, "render": {"mode": "direct", "spp": 2, "adaptive_spp": 7},
   "materials": {"f": {"albedo": 0.5}},
   "shapes": [{"type": "quad", "corners": [[-50,0,-50],[50,0,-50],[50,0,50],[-50,0,50]], "material": "f"}],
   "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2}]})";
  Report report;
  const RenderResult r = renderText(text, &report);
  for (const RGB& p : r.image.pixels) EXPECT_NEAR(p.x, 1.0 / std::numbers::pi, 1e-6);
  EXPECT_EQ(report.count("adaptive_samples"), 5u * 30u);
  EXPECT_EQ(report.count("camera_rays"), 7u * 30u);
}

// Over 12 seeds the adaptive pixels' mean error, summed over the image with its sign, is
// within 4 standard errors of zero, and their absolute error is below 0.85 of what even
// samples give at the same mean count (the samples go to the edges; measured: 0.70; the
// even pixels' 8 samples are stratified, so their edges are already good).
TEST(AdaptiveSamples, EdgesTakeTheSamplesAndStayUnbiased) {
  const Image reference = renderText(edgeScene(1024, 0, 99)).image;
  double adaptiveError = 0.0, evenError = 0.0;
  std::vector<double> signedSum;
  for (uint64_t seed = 1; seed <= 12; ++seed) {
    const Image adaptive = renderText(edgeScene(2, 8, seed)).image;
    const Image even = renderText(edgeScene(8, 0, seed)).image;
    adaptiveError += sumAbsDifference(adaptive, reference);
    evenError += sumAbsDifference(even, reference);
    double s = 0.0;
    for (size_t i = 0; i < adaptive.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c) s += adaptive.pixels[i][c] - reference.pixels[i][c];
    signedSum.push_back(s);
  }
  EXPECT_LT(adaptiveError, 0.85 * evenError);
  double mean = 0.0, var = 0.0;
  for (double s : signedSum) mean += s / static_cast<double>(signedSum.size());
  for (double s : signedSum)
    var += (s - mean) * (s - mean) / static_cast<double>(signedSum.size() - 1);
  EXPECT_LT(std::abs(mean), 4.0 * std::sqrt(var / static_cast<double>(signedSum.size())) + 1e-6);
}

TEST(AdaptiveSamples, TheImageDoesNotDependOnTheThreads) {
  const Image one = renderText(edgeScene(2, 6, 3), nullptr, 1).image;
  const Image two = renderText(edgeScene(2, 6, 3), nullptr, 2).image;
  EXPECT_EQ(sumAbsDifference(one, two), 0.0);
}

TEST(AdaptiveSamples, ABudgetAtOrBelowTheSamplesIsAnError) {
  try {
    parseScene(edgeScene(4, 4, 1), "/tmp/adaptive-test.json");
    FAIL() << "adaptive_spp 4 with spp 4 was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("render.adaptive_spp"), std::string::npos) << e.what();
  }
  Scene scene = parseScene(edgeScene(2, 6, 1), "/tmp/adaptive-test.json");
  RenderPlan plan;
  plan.spp = 2;
  plan.firstSample = 8;
  Report report;
  EXPECT_THROW(renderScene(scene.job(), plan, report), InputError);
}

TEST(AdaptiveSamples, AutoIsThreeHalvesOfTheSamplesInThePcbModesOnly) {
  RenderSettings s;
  ASSERT_EQ(s.adaptiveSpp, RenderSettings::kAutoAdaptive);
  for (auto [mode, spp, expected] : {std::tuple{Mode::kPcb, 4, 6},
                                     {Mode::kPcbSurfels, 5, 8},
                                     {Mode::kPcb, 1, 0},
                                     {Mode::kMc, 4, 0},
                                     {Mode::kDirect, 16, 0}}) {
    s.mode = mode;
    s.spp = spp;
    EXPECT_EQ(adaptiveSamplesFor(s), expected) << modeName(mode) << " at " << spp << " spp";
  }
  s.adaptiveSpp = 0;
  s.mode = Mode::kPcb;
  EXPECT_EQ(adaptiveSamplesFor(s), 0);
}

// Under "auto" a render that cannot take adaptive samples (here: chunk 2 of a longer run)
// takes even ones and warns; given in the scene, the same plan is an error (above).
TEST(AdaptiveSamples, AutoGivesWayToChunksWithAWarning) {
  std::string text = edgeScene(2, 6, 1);
  const std::string given = R"("adaptive_spp": 6)";
  text.replace(text.find(given), given.size(), R"("adaptive_spp": "auto", "mode": "pcb")");
  text.replace(text.find(R"("mode": "direct", )"), 18, "");
  Scene scene = parseScene(text, "/tmp/adaptive-test.json");
  RenderPlan plan;
  plan.spp = 2;
  plan.firstSample = 2;
  Report report;
  renderScene(scene.job(), plan, report);
  EXPECT_EQ(report.count("adaptive_samples"), 0u);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("adaptive samples are off"), std::string::npos);
}

}  // namespace
}  // namespace lvox
