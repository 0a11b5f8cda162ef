#pragma once
// Delta tracking (free-flight sampling) and ratio tracking (transmittance) through the
// scene's media against piecewise-constant majorants (MajorantSpan: >= sigma_t of every
// channel on the span): per block of a VDB grid at the level that pays for that medium
// (8^3 or 64^3 voxels, from the tree's own nodes) or one global majorant per medium, so
// the reference can be timed both ways. Homogeneous media have an exact majorant (no null
// collisions) and analytic transmittance.
#include <cmath>
#include <vector>

#include "src/core/rng.h"
#include "src/core/sampling.h"
#include "volume/media/media_set.h"

namespace lvox {

// Tentative collisions along majorant segments, the loop shared by delta tracking (free
// flights) and ratio tracking (transmittance): exponential steps at the segment's majorant;
// `collision(t, majorant)` is called at each one and stops the walk by returning false.
// Returns false when stopped.
//
// Every step moves t by at least one float ulp: with a majorant far above 1/ulp(t) (sigma
// 1e9 five units from the camera) an exponential step would round to nothing, and a
// point on a medium's boundary that the medium does not contain would repeat forever.
template <class Collision>
bool forEachTentativeCollision(const std::vector<MajorantSpan>& segments, Rng& rng,
                               Collision&& collision) {
  for (const MajorantSpan& s : segments) {
    if (!(s.majorant > 0.0f) || !std::isfinite(s.majorant)) continue;
    float t = s.t0;
    while (true) {
      const float next = t + sampleExponential(rng.uniform(), s.majorant);
      t = next > t ? next : std::nextafter(t, s.t1 + 1.0f);
      if (t >= s.t1) break;
      if (!collision(t, s.majorant)) return false;
    }
  }
  return true;
}

class MajorantTracker {
 public:
  MajorantTracker(const MediaSet& media, bool useGrid) : media_(media), useGrid_(useGrid) {}

  // Piecewise-constant majorant of all media (or of the heterogeneous ones only) along
  // [tmin, tmax]; pieces with majorant 0 are left out.
  void segments(const Ray& ray, float tmin, float tmax, bool heterogeneousOnly,
                std::vector<MajorantSpan>& out) const;

  // Transmittance along [ray.tmin, ray.tmax]: exact through homogeneous media, ratio
  // tracking through the others (unbiased). `lookups` counts medium evaluations.
  RGB transmittance(const Ray& ray, Rng& rng, uint64_t& lookups) const;

  const MediaSet& media() const { return media_; }

 private:
  const MediaSet& media_;
  bool useGrid_;
};

}  // namespace lvox
