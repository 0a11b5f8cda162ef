#pragma once
// A node's surfels seen from far away, with direction (Christensen 2008, "Point-based
// approximate color bleeding"): the spherical harmonics (bands 0-2) of the light the
// cluster sends out and of the area it shows, per direction.
//
// Every side of a surfel that open space can see (SurfelSet::enclosedSides) is a one-sided
// emitter of area A, normal m (the side's) and radiance L: seen from direction w it shows
// the area A max(0, m.w) and sends the power (per solid angle) A L max(0, m.w). Summed
// over the cluster's surfels these are `openArea` and `power`. Enclosed sides (the inside
// of a column or a box) show nothing, so a closed object in one cluster shows its
// silhouette and the radiance of the faces turned to the viewer.
//
// Christensen's cluster radiance is power / area, both truncated to the same bands. For a
// flat cluster that ratio is 1/2 + t / (2 |t|_2), with |t|_2 = (3 + 15 t^2) / 16 the
// band-limited |t|: 0.94 of the radiance seen head-on, 1.09 at 60 degrees, and a wall lit
// on one side shows 6 % of its front's radiance from behind. The band-1 parts are exact
// (the odd part of max(0, t) is t / 2); the error is all in the even parts. Their
// band-limited |t| is undone with the cluster's exact projected area, which the coverage
// uses anyway: for any cluster the truncated two-sided area is area (3 + 15 q) / 16 with
// q = w^T M w (M the mean n n^T: the band-2 sum of a surfel is 5 P2(n.w), linear in
// n n^T), and the projection of the disks is area sqrt(q) (exact for flat clusters), so
// the even parts are scaled by 16 sqrt(q) / (3 + 15 q). A flat cluster's radiance and
// coverage are then exact from either side; curved and closed ones are approximated
// smoothly (docs/pointcloud.md, "Cluster aggregates"; measured in docs/results.md,
// "Directional surfel clusters").
//
// The cluster's radiance along a ray is linear in `power`, with weights that depend on the
// geometry only (radianceWeights()): the gather operator records them like any other
// weight.
#include <algorithm>
#include <cmath>

#include "src/core/math.h"
#include "src/core/spherical_harmonics.h"

namespace lvox {

// Coefficients of max(0, m.w) in the basis of spherical_harmonics.h: h_l Yhat_k(m), with
// h_l = (1/2) integral over t in [0, 1] of t P_l(t): 1/4, 1/6, 1/16 (Funk-Hecke).
inline void clampedCosineCoefficients(const Vec3& m, float* c) {
  constexpr float kZonal[kShBands] = {0.25f, 1.0f / 6.0f, 1.0f / 16.0f};
  shBasis(m, kShCoefficients, c);
  for (int k = 0; k < kShCoefficients; ++k) c[k] *= kZonal[shBand(k)];
}

struct SurfelCluster {
  // The box the cluster covers: the union of squares of side 2 sqrt(area) around the
  // surfels (tilted like the disks; twice the equal-area side so they reach the cell
  // walls between lattice rows), clipped to the node's octree cell, so that the boxes of
  // neighbouring clusters on one surface nearly tile it.
  Bounds3 cover;
  Vec3 centroid{0, 0, 0};
  float area = 0.0f;                     // represented surface area, sum of pi r^2 / radiusScale^2
  float diskArea = 0.0f;                 // sum of pi r^2
  float moment[6] = {0, 0, 0, 0, 0, 0};  // xx, yy, zz, xy, xz, yz of the mean n n^T
  float openArea[kShCoefficients] = {};  // of sum A max(0, m.w) over open sides
  RGB power[kShCoefficients];            // of sum A L max(0, m.w) over open sides

  SurfelCluster() { std::fill(power, power + kShCoefficients, RGB(0.0f)); }

  // q = w^T M w: sqrt(q) is the disks' projected area per unit area, exact when flat.
  float projectedSquare(const Vec3& d) const {
    const float q = moment[0] * d.x * d.x + moment[1] * d.y * d.y + moment[2] * d.z * d.z +
                    2.0f * (moment[3] * d.x * d.y + moment[4] * d.x * d.z + moment[5] * d.y * d.z);
    return std::clamp(q, 0.0f, 1.0f);
  }

  // Seen along a ray of direction d (towards the cluster): into `g` the weights of the
  // power coefficients (the SH of -d, even bands rescaled as above), and the open area
  // shown, sum of openArea[k] g[k]: 0 where that is rounding (a flat cluster seen from an
  // enclosed side) or negative.
  float shownArea(const Vec3& d, float* g) const {
    shBasis(-d, kShCoefficients, g);
    const float q = projectedSquare(d);
    const float evenScale = 16.0f * std::sqrt(q) / (3.0f + 15.0f * q);
    float shown = 0.0f;
    for (int k = 0; k < kShCoefficients; ++k) {
      if (shBand(k) != 1) g[k] *= evenScale;
      shown += openArea[k] * g[k];
    }
    return shown > 1e-5f * area ? shown : 0.0f;
  }

  // The fraction of the cover box's projection the open sides block, capped at 1: the
  // projected area of their disks (shown area times diskArea / area) over the box's. The
  // disks' sum exceeds the box for surfaces covered without holes, where the cap gives the
  // exact coverage 1 (the represented area alone would leave 10-20% spurious holes from
  // the lattice's count fluctuations per cell).
  float coverage(const Vec3& d, float shown) const {
    const Vec3 e = cover.diagonal();
    const float box =
        std::abs(d.x) * e.y * e.z + std::abs(d.y) * e.x * e.z + std::abs(d.z) * e.x * e.y;
    if (!(box > 0.0f) || !(area > 0.0f)) return 0.0f;
    return std::min(1.0f, diskArea / area * shown / box);
  }
  float coverage(const Vec3& d) const {
    float g[kShCoefficients];
    return coverage(d, shownArea(d, g));
  }

  // Radiance seen along d is sum power[k] w[k]: w = g / shown area (0 where nothing shows).
  // Returns false where nothing shows.
  bool radianceWeights(const Vec3& d, float* w) const {
    const float shown = shownArea(d, w);
    if (!(shown > 0.0f)) return false;
    for (int k = 0; k < kShCoefficients; ++k) w[k] /= shown;
    return true;
  }
  RGB radiance(const Vec3& d) const {
    float w[kShCoefficients];
    if (!radianceWeights(d, w)) return RGB(0.0f);
    RGB sum(0.0f);
    for (int k = 0; k < kShCoefficients; ++k) sum += power[k] * w[k];
    return nonNegative(sum);
  }
};

}  // namespace lvox
