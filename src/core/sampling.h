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

}  // namespace lvox
