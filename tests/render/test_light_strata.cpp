// The samples one forEachAreaSample call draws of a light are stratified over it
// (src/render/light_set.h): their estimate is unbiased and much less noisy than that of as
// many independent samples, for an emitter's irradiance at a point (smooth: the error
// falls about as N^-1 instead of N^-0.5) and for the share of a uniform sky seen through
// a window (an edge: about N^-0.75).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "square_lamp.h"
#include "src/render/light_set.h"

namespace lvox {
namespace {

constexpr int kSamples = 16;
constexpr int kCalls = 4000;

struct Spread {
  double mean, rms;  // the estimates' mean and their RMS deviation from it
};

Spread spread(const std::function<double(int call)>& estimate) {
  double sum = 0.0, sum2 = 0.0;
  for (int c = 0; c < kCalls; ++c) {
    const double e = estimate(c);
    sum += e;
    sum2 += e * e;
  }
  const double mean = sum / kCalls;
  return {mean, std::sqrt(std::max(0.0, sum2 / kCalls - mean * mean))};
}

// Both estimators unbiased: their means agree within 5 standard errors of the difference.
void expectSameMean(const Spread& a, const Spread& b) {
  const double se = std::sqrt((a.rms * a.rms + b.rms * b.rms) / kCalls);
  EXPECT_NEAR(a.mean, b.mean, 5.0 * se);
}

TEST(LightStrata, AreaLightSamplesOfOneCallAreStratified) {
  const World world = test::squareLampWorld(1.0f);
  const LightSet strata(world, kSamples), single(world, 1);
  const Vec3 p(0.3f, -0.2f, 0.0f), n(0.0f, 0.0f, 1.0f);
  const Spread stratified = spread([&](int call) {
    Rng rng(5, static_cast<uint64_t>(call));
    double e = 0.0;  // irradiance: the samples come weighted 1/N
    strata.forEachAreaSample(p, &n, rng, [&](const LightSample& s) {
      e += s.radiance.x * std::max(0.0f, dot(s.wi, n));
    });
    return e;
  });
  const Spread independent = spread([&](int call) {
    Rng rng(6, static_cast<uint64_t>(call));
    double e = 0.0;
    for (int i = 0; i < kSamples; ++i) {
      const LightSample s = single.sampleArea(p, rng);
      e += s.radiance.x * std::max(0.0f, dot(s.wi, n)) / kSamples;
    }
    return e;
  });
  expectSameMean(stratified, independent);
  EXPECT_LT(stratified.rms, 0.5 * independent.rms)
      << stratified.rms << " against " << independent.rms;
}

TEST(LightStrata, SkySamplesOfOneCallAreStratified) {
  World world;
  Light sky;
  sky.type = LightType::Environment;
  sky.intensity = RGB(1.0f);
  world.lights.push_back(sky);
  const LightSet strata(world, kSamples), single(world, 1);
  const Vec3 p(0.0f), n = normalize(Vec3(0.1f, 0.2f, 1.0f));
  // The sky's irradiance through a window: directions with x > 0.3.
  const auto window = [&](const LightSample& s) {
    return s.wi.x > 0.3f ? s.radiance.x * std::max(0.0f, dot(s.wi, n)) : 0.0f;
  };
  const Spread stratified = spread([&](int call) {
    Rng rng(7, static_cast<uint64_t>(call));
    double e = 0.0;
    strata.forEachAreaSample(p, &n, rng, [&](const LightSample& s) { e += window(s); });
    return e;
  });
  const Spread independent = spread([&](int call) {
    Rng rng(8, static_cast<uint64_t>(call));
    double e = 0.0;
    for (int i = 0; i < kSamples; ++i)
      single.forEachAreaSample(p, &n, rng,
                               [&](const LightSample& s) { e += window(s) / kSamples; });
    return e;
  });
  expectSameMean(stratified, independent);
  EXPECT_LT(stratified.rms, 0.5 * independent.rms)
      << stratified.rms << " against " << independent.rms;
}

}  // namespace
}  // namespace lvox
