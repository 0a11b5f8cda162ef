#pragma once
// The weights an lvoxel's gather gives its own cube, from a fixed quadrature instead of
// the gather's random rays (docs/pcb.md, "The own cube").
//
// The interreflection traces each lvoxel's rays once and applies them in every pass, so
// light that scatters many times within one cube meets the same random self-weight at
// every step: the mean of its powers is above the power of its mean, and in a thick white
// medium the self-weight is the largest weight of the row. Seen from its centre, the
// cube's weight along d is w(d) = 1 - exp(-sigma_t chord(d)), a function of its optical
// half-size alone. Over the face whose axis dominates d = (x, y, 1) / r, r = sqrt(1 + x^2 +
// y^2), the chord is h r and the solid angle dx dy / r^3: a Gauss-Legendre product rule of
// 8 x 8 nodes on a quarter of a face (the rest alike by symmetry) integrates it, and its
// products with the quartics below, to 1e-9 (on the whole face: 1e-4).
//
// A gather projects its light on spherical harmonics of bands 0-2 at most, products of
// which are polynomials of degree 4 or less in d; w has the cube's symmetry, and against a
// measure with that symmetry only the symmetric polynomials count: up to degree 4 these
// are 1 and x^4 + y^4 + z^4 (on the sphere). So two weights, one on the 6 axes and one on
// the 8 corners, matched to those two integrals, give the cube's exact coupling of every
// harmonic with every other: 14 directions stand in for the integral.
#include <algorithm>
#include <cmath>

#include "pointcloud/lvoxels.h"
#include "src/core/math.h"
#include "src/geometry/ray_tracer.h"

namespace lvox {

// Whether a surface passes through the cube of half-size h about c: one of the segments
// from c to its corners is blocked. Every plane that leaves part of the cube on the far
// side from c leaves a corner there, so it crosses that corner's segment; a small object
// wholly inside the cube can be missed. A surface on a face (a wall along the grid) does
// not count: the segments stop just short of the corners.
inline bool surfaceCutsCube(const RayTracer& tracer, const Vec3& c, float h) {
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner(k & 1 ? h : -h, k & 2 ? h : -h, k & 4 ? h : -h);
    if (tracer.blocked(c, c + corner)) return true;
  }
  return false;
}

// Whether a surface cuts lvoxel i's cube, for a gather at p: the mark the renderer made
// (LvoxelSet::cut, the same test) when the gather is at the cube's centre, else the test.
inline bool ownCubeCut(const LvoxelSet& lvoxels, size_t i, const Vec3& p, const RayTracer& tracer) {
  if (!lvoxels.cut.empty() && p == lvoxels.position[i]) return lvoxels.cut[i] != 0;
  return surfaceCutsCube(tracer, p, lvoxels.halfSize[i]);
}

// The weights of the own cube's 14 directions: `axis` on each of the 6 axes, `corner` on
// each of the 8 diagonals, per colour.
struct OwnCubeWeights {
  RGB axis{0.0f};
  RGB corner{0.0f};
};

namespace own_cube {
inline constexpr double kNodes[] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                    -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                    0.7966664774136267,  0.9602898564975363};
inline constexpr double kWeights[] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                      0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                      0.2223810344533745, 0.1012285362903763};

// 1 - exp(-sigma_t chord), one exponential for grey media.
inline RGB absorbed(const RGB& sigmaT, float chord) {
  return sigmaT.x == sigmaT.y && sigmaT.y == sigmaT.z ? RGB(1.0f - std::exp(-sigmaT.x * chord))
                                                      : RGB(1.0f) - exp(-sigmaT * chord);
}
}  // namespace own_cube

// The own cube's weights for a gather that weighs directions by the isotropic phase
// 1 / (4 pi): the integrals of w / (4 pi) and w (x^4 + y^4 + z^4) / (4 pi) over the
// sphere by the 8 x 8 rule on a quarter face (64 nodes), then the axis and corner weights
// that give both. Both are never negative: x^4 + y^4 + z^4 lies in [1/3, 1].
inline OwnCubeWeights ownCubeWeights(const RGB& sigmaT, float h) {
  using namespace own_cube;
  RGB total(0.0f), quartic(0.0f);
  for (int a = 0; a < 8; ++a)
    for (int b = 0; b < 8; ++b) {
      // The nodes on [0, 1]: a quarter of the face, the other three alike.
      const double x = 0.5 * (kNodes[a] + 1.0), y = 0.5 * (kNodes[b] + 1.0);
      const double r2 = 1.0 + x * x + y * y;
      const double r = std::sqrt(r2);
      const double dw = 0.25 * kWeights[a] * kWeights[b] / (r2 * r) / (4.0 * kPi);
      const double q = (1.0 + x * x * x * x + y * y * y * y) / (r2 * r2);
      // Six faces of four quarters each.
      const RGB w = absorbed(sigmaT, h * static_cast<float>(r)) * static_cast<float>(24.0 * dw);
      total += w;
      quartic += w * static_cast<float>(q);
    }
  // 6 axis + 8 corner = total; 6 axis + 8 corner / 3 = quartic.
  OwnCubeWeights out;
  out.corner = (total - quartic) * (3.0f / 16.0f);
  out.axis = (total - out.corner * 8.0f) * (1.0f / 6.0f);
  return out;
}

// Sends the sink lvoxel i's own-cube weights, each of the 14 directions as a ray.
template <class Sink>
void ownCubeInto(const LvoxelSet& lvoxels, uint32_t i, Sink& sink) {
  const OwnCubeWeights w = ownCubeWeights(lvoxels.sigmaT(i), lvoxels.halfSize[i]);
  for (int axis = 0; axis < 3; ++axis)
    for (int sign = -1; sign <= 1; sign += 2) {
      Vec3 d(0.0f, 0.0f, 0.0f);
      d[axis] = static_cast<float>(sign);
      sink.beginRay(d);
      sink.lvoxel(i, w.axis);
    }
  const float c = 1.0f / std::sqrt(3.0f);
  for (int k = 0; k < 8; ++k) {
    sink.beginRay(Vec3(k & 1 ? c : -c, k & 2 ? c : -c, k & 4 ? c : -c));
    sink.lvoxel(i, w.corner);
  }
}

}  // namespace lvox
