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

namespace lvox {

// Three bands (a fourth was measured and not kept: docs/pcb.md; its basis is in the
// history of this file, commit a898b88).
inline constexpr int kShBands = 3;
inline constexpr int kShCoefficients = kShBands * kShBands;

// The band l of coefficient k (0; 1, 1, 1; 2, 2, 2, 2, 2).
constexpr int shBand(int k) { return k == 0 ? 0 : (k < 4 ? 1 : 2); }

// Yhat_k(d) for the first `count` coefficients (1, 4 or 9) of a unit vector d.
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
}

// sum over k < count of c[k] * y[k], a radiance: clamped at zero, since a band-limited
// expansion of a non-negative function can dip below it (count 1: c[0] itself).
inline RGB shDot(const RGB* c, const float* y, int count) {
  RGB sum = c[0] * y[0];
  for (int k = 1; k < count; ++k) sum += c[k] * y[k];
  return nonNegative(sum);
}

}  // namespace lvox
