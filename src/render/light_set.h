#pragma once
// Every light of a scene behind one sampling interface: point, spot, directional and
// environment lights from the scene file, and area lights made of emissive triangles.
#include <cmath>
#include <vector>

#include "src/core/low_discrepancy.h"
#include "src/core/rng.h"
#include "src/core/sampling.h"
#include "src/world/world.h"

namespace lvox {

// One sample of light arriving at a point: from direction `wi` (unit, towards the light)
// over a distance `distance` (infinite for directional and environment light).
// `radiance` is the unoccluded contribution already divided by the sampling pdf, so an
// estimator sums f(wi) * radiance (times visibility and transmittance) over samples.
struct LightSample {
  Vec3 wi;
  float distance = kInf;
  RGB radiance{0.0f};
  bool fromEmitter = false;      // an area-light sample: its distance ends on the emitter
  bool fromEnvironment = false;  // an environment-map sample (importance-sampled)
  float pdf = 0.0f;  // solid-angle pdf of an area-light or environment-map sample (for MIS)
};

// The shadow ray from a point in a medium (no surface to step off) towards a light along
// `wi`, stopping just short of a light `distance` away (infinite: never).
inline Ray shadowRayFrom(const Vec3& x, const Vec3& wi, float distance) {
  return Ray{x, wi, 0.0f, std::isinf(distance) ? kInf : distance * (1.0f - 1e-4f)};
}

class LightSet {
 public:
  LightSet(const World& world, int areaSamples);

  // Calls f(sample) for each light sample seen from `p`. Delta lights give one sample
  // each; area and environment lights give `areaSamples` samples each, weighted 1/N.
  // With `normal`, a constant environment is sampled cosine-weighted about it (surfaces);
  // without, uniformly over the sphere (media). An environment map is importance-sampled
  // by its own radiance.
  template <class F>
  void forEachSample(const Vec3& p, const Vec3* normal, Rng& rng, F&& f) const {
    forEachDeltaSample(p, f);
    forEachAreaSample(p, normal, rng, f);
  }
  // Only the point, spot and directional lights (no random numbers).
  template <class F>
  void forEachDeltaSample(const Vec3& p, F&& f) const;
  // Only the environment and the emissive triangles; without the constant environment's
  // samples when a cache gives its light (src/render/environment_cache.h).
  template <class F>
  void forEachAreaSample(const Vec3& p, const Vec3* normal, Rng& rng, F&& f,
                         bool constantEnvironment = true) const;

  bool hasAreaLights() const { return !emissiveTriangles_.empty(); }
  float emissiveArea() const { return totalArea_; }
  const std::vector<Light>& lights() const { return lights_; }
  RGB environment() const { return environment_; }
  // Radiance of the environment (constant and map) from direction `dir`.
  RGB environment(const Vec3& dir) const {
    return map_ ? environment_ + map_->radiance(dir) : environment_;
  }
  // The environment's lat-long map, importance-sampled by forEachAreaSample (nullptr: none).
  const EnvironmentMap* environmentMap() const { return map_; }

  // Unoccluded sample of one point/spot/directional light at p.
  LightSample sampleDelta(const Light& light, const Vec3& p) const;
  // A sample of the emissive triangles seen from p: a triangle picked by area, then a
  // direction uniform over the solid angle it subtends (SphericalTriangle), or a point
  // uniform over its area where it subtends less than kMinSphericalSolidAngle or nearly
  // a hemisphere (where the spherical formulas lose precision).
  LightSample sampleArea(const Vec3& p, Rng& rng) const;
  // The same from a point of the unit square (32-bit fixed point): u picks the triangle
  // by area, and where it fell in that triangle's share, with v, the point in it, so that
  // stratified points stay stratified over the emitters.
  LightSample sampleArea(const Vec3& p, FixedPoint2 point) const;
  // Solid-angle pdf with which sampleArea, from p, picks the direction that reaches
  // emissive triangle `triangle` (a mesh index) at `distance` under `cosLight` (MIS).
  float emitterPdf(const Vec3& p, uint32_t triangle, float distance, float cosLight) const;
  static constexpr double kMinSphericalSolidAngle = 3e-4;  // sr
  static constexpr double kMaxSphericalSolidAngle = 6.22;  // sr, 2 pi less about 1 %

 private:
  const World& world_;
  std::vector<Light> lights_;  // point, spot, directional
  RGB environment_{0.0f};
  const EnvironmentMap* map_ = nullptr;
  std::vector<uint32_t> emissiveTriangles_;
  std::vector<float> areaCdf_;  // cumulative area, normalised to end at 1
  float totalArea_ = 0.0f;
  int areaSamples_ = 1;
};

template <class F>
void LightSet::forEachDeltaSample(const Vec3& p, F&& f) const {
  for (const Light& light : lights_) {
    LightSample s = sampleDelta(light, p);
    if (!isBlack(s.radiance)) f(s);
  }
}

// The N samples of one light in one call are the first N points of an Owen-scrambled
// (0,2)-sequence, scrambled afresh for the call and the light (low_discrepancy.h): each is
// uniform, and together they are stratified over the light's domain (exactly, when N is a
// power of two). 16 such samples of an emitter's irradiance, or of a sky seen through a
// window, are 0.34-0.40 as noisy as 16 independent ones (tests/render/test_light_strata.cpp).
template <class F>
void LightSet::forEachAreaSample(const Vec3& p, const Vec3* normal, Rng& rng, F&& f,
                                 bool constantEnvironment) const {
  const float weight = 1.0f / static_cast<float>(areaSamples_);
  const auto scrambled = [&rng] {
    const uint32_t seedU = rng.next(), seedV = rng.next();
    return [seedU, seedV](int i) {
      return scrambledSobol2Fixed(static_cast<uint32_t>(i), seedU, seedV);
    };
  };
  if (constantEnvironment && !isBlack(environment_)) {
    const auto points = scrambled();
    for (int i = 0; i < areaSamples_; ++i) {
      LightSample s;
      const FixedPoint2 q = points(i);
      const float u1 = fixedPointToUnit(q.u), u2 = fixedPointToUnit(q.v);
      if (normal) {
        // Cosine sampling: pdf = cos/pi, so radiance/pdf = L pi / cos; the caller's cos
        // cancels it.
        const Vec3 local = cosineHemisphere(u1, u2);
        s.wi = Frame(*normal).toWorld(local);
        const float pdf = std::max(cosineHemispherePdf(local.z), 1e-8f);
        s.radiance = environment_ * (weight / pdf);
      } else {
        s.wi = uniformSphere(u1, u2);
        s.radiance = environment_ * (weight / kUniformSpherePdf);
      }
      f(s);
    }
  }
  if (map_) {
    const auto points = scrambled();
    for (int i = 0; i < areaSamples_; ++i) {
      LightSample s;
      const FixedPoint2 q = points(i);
      const float u1 = fixedPointToUnit(q.u), u2 = fixedPointToUnit(q.v);
      s.wi = map_->sample(u1, u2, s.pdf);
      if (!(s.pdf > 0.0f)) continue;
      s.radiance = map_->radiance(s.wi) * (weight / s.pdf);
      s.fromEnvironment = true;
      f(s);
    }
  }
  if (!emissiveTriangles_.empty()) {
    const auto points = scrambled();
    for (int i = 0; i < areaSamples_; ++i) {
      LightSample s = sampleArea(p, points(i));
      if (!isBlack(s.radiance)) {
        s.radiance *= weight;
        f(s);
      }
    }
  }
}

}  // namespace lvox
