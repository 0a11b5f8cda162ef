#pragma once
// Real spherical harmonics of bands l = 0, 1, 2 (9 functions), scaled by 1 / Y_00 =
// 2 sqrt(pi) so that the first one is 1: with this basis a function's first coefficient
// is its mean over the sphere, c_lm = (1 / 4 pi) integral f Yhat_lm dw, and
// f = sum c_lm Yhat_lm. An isotropic quantity is then just its first coefficient, with
// no constant to carry around (the point cloud's lvoxels store one coefficient per
// colour in isotropic media and nine in anisotropic ones).
//
// Convolution with a phase function (Funk-Hecke): the light a medium scatters towards
// wo, integral of p(dot(-wi, wo)) L(wi) dwi over the incoming directions wi, is
// sum over l, m of chi_l c_lm Yhat_lm(-wo), chi_l the phase's Legendre moments
// (PhaseFunction::moment; g^l for Henyey-Greenstein).
#include "src/core/math.h"

#ifndef LVOX_SH_BANDS
#define LVOX_SH_BANDS 3
#endif

namespace lvox {

inline constexpr int kShBands = LVOX_SH_BANDS;
inline constexpr int kShCoefficients = kShBands * kShBands;

// The band l of coefficient k (0; 1, 1, 1; 2, 2, 2, 2, 2; 3 ...).
constexpr int shBand(int k) { return k == 0 ? 0 : (k < 4 ? 1 : (k < 9 ? 2 : 3)); }

// Yhat_k(d) for the first `count` coefficients (1, 4, 9 or 16) of a unit vector d.
inline void shBasis(const Vec3& d, int count, float* y) {
  y[0] = 1.0f;
  if (count <= 1) return;
  constexpr float kL1 = 1.7320508f;   // sqrt(3)
  constexpr float kL2 = 3.8729833f;   // sqrt(15)
  constexpr float kL20 = 1.1180340f;  // sqrt(5) / 2
  constexpr float kL22 = 1.9364917f;  // sqrt(15) / 2
  y[1] = kL1 * d.y;
  y[2] = kL1 * d.z;
  y[3] = kL1 * d.x;
  if (count <= 4) return;
  y[4] = kL2 * d.x * d.y;
  y[5] = kL2 * d.y * d.z;
  y[6] = kL20 * (3.0f * d.z * d.z - 1.0f);
  y[7] = kL2 * d.x * d.z;
  y[8] = kL22 * (d.x * d.x - d.y * d.y);
  if constexpr (kShBands < 4) return;  // (and no band 3 to fill in arrays of kShCoefficients)
  if (count <= 9) return;
  constexpr float kL33 = 2.0916500f;   // sqrt(35 / 8)
  constexpr float kL32 = 10.2469508f;  // sqrt(105)
  constexpr float kL31 = 1.6201852f;   // sqrt(21 / 8)
  constexpr float kL30 = 1.3228757f;   // sqrt(7) / 2
  const float z2 = d.z * d.z;
  y[9] = kL33 * d.y * (3.0f * d.x * d.x - d.y * d.y);
  y[10] = kL32 * d.x * d.y * d.z;
  y[11] = kL31 * d.y * (5.0f * z2 - 1.0f);
  y[12] = kL30 * d.z * (5.0f * z2 - 3.0f);
  y[13] = kL31 * d.x * (5.0f * z2 - 1.0f);
  y[14] = 0.5f * kL32 * d.z * (d.x * d.x - d.y * d.y);
  y[15] = kL33 * d.x * (d.x * d.x - 3.0f * d.y * d.y);
}

// sum over k < count of c[k] * y[k], a radiance: clamped at zero, since a band-limited
// expansion of a non-negative function can dip below it (count 1: c[0] itself).
inline RGB shDot(const RGB* c, const float* y, int count) {
  RGB sum = c[0] * y[0];
  for (int k = 1; k < count; ++k) sum += c[k] * y[k];
  return {std::max(sum.x, 0.0f), std::max(sum.y, 0.0f), std::max(sum.z, 0.0f)};
}

}  // namespace lvox
