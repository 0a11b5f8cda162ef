#pragma once
// Sample warps from the unit square; each returns a direction/point and its pdf.
#include "src/core/math.h"

namespace lvox {

inline Vec3 cosineHemisphere(float u1, float u2) {
  // Malley's method: concentric disk lifted to the hemisphere.
  const float r = std::sqrt(u1);
  const float phi = 2.0f * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u1))};
}
inline float cosineHemispherePdf(float cosTheta) { return cosTheta * kInvPi; }

inline Vec3 uniformSphere(float u1, float u2) {
  const float z = 1.0f - 2.0f * u1;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline constexpr float kUniformSpherePdf = 1.0f / (4.0f * kPi);

// Uniform barycentrics on a triangle (Heitz 2019 is nicer; the square-root map is exact).
inline void uniformTriangle(float u1, float u2, float& b1, float& b2) {
  const float su = std::sqrt(u1);
  b1 = 1.0f - su;
  b2 = u2 * su;
}

// Free-flight distance in a medium of extinction sigma: pdf sigma exp(-sigma t) on
// [0, inf). 1 - u lies in (0, 1], so the distance is finite.
inline float sampleExponential(float u, float sigma) { return -std::log(1.0f - u) / sigma; }

// Equiangular distance sampling on [a, b] of a ray (Kulla & Fajardo 2012) for a point at
// distance h from the ray whose foot lies at t = delta: pdf proportional to
// 1 / (h^2 + (t - delta)^2), the falloff of a point light's contribution along the ray.
struct EquiangularSampler {
  float delta, h, thetaA, thetaB;
  EquiangularSampler(float delta_, float h_, float a, float b)
      : delta(delta_),
        h(h_),
        thetaA(std::atan((a - delta_) / h_)),
        thetaB(std::atan((b - delta_) / h_)) {}
  // False for an empty (or NaN) angle range: nothing to sample.
  bool valid() const { return thetaB > thetaA; }
  float sample(float u) const { return delta + h * std::tan(thetaA + u * (thetaB - thetaA)); }
  float pdf(float t) const { return h / ((thetaB - thetaA) * (h * h + (t - delta) * (t - delta))); }
};

}  // namespace lvox
