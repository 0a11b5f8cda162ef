#pragma once
// `--solver auto`: the method and settings each ray segment needs (docs/solvers.md, "auto").
//   - Homogeneous media that only absorb and emit: coefficients and source are constant
//     between box faces, so one exact exponential step per piece (left-point marching
//     integrates a constant piece exactly).
//   - Every medium on the segment homogeneous: sigma_t is constant between the media's
//     box faces, so only the source varies. Adaptive Gauss-Kronrod on the integral form,
//     with the equiangular change of variable around the brightest point or spot light
//     (its 1/r^2 peak becomes flat). First panels are equal in that variable (in t
//     without a point light), and where it is densest no two of their nodes are further
//     apart than the scene's step or, without one, the scale of the shadows cast into the
//     media (src/render/medium_scale.h); integration stops where T < 1e-7.
//   - A heterogeneous medium on the segment: RK4 at a step relative to the medium, not to
//     the scene's units: 1.2 steps per narrowest density bump (2 voxels under trilinear
//     interpolation, half a noise period), split where the medium is denser so that no
//     step spans more than 0.6 optical depths (the local sigma_t, at the step's start and
//     stages), both scaled by (tolerance / 1e-3)^(1/4). Neither the scene's step nor
//     max_step enters. (dopri5 at the tolerance cost more for the same error on the
//     smooth plume and the noise field; docs/results.md.)
//   - Spot beams: the ray's crossings of each cone (outer and inner edge) are breakpoints,
//     so no step or panel straddles a beam edge, and inside a beam the step is capped by
//     the beam's width, so shadows at that scale are resolved. A thin beam is never skipped.
//   - Box faces of the media are breakpoints (sigma_t jumps there).
//   - Shadow rays: analytic through homogeneous media (as for every method); through
//     heterogeneous ones RK4 at the same relative step.
//   - Empty space costs nothing: only the media's occupied intervals are integrated.
#include <vector>

#include "src/render/medium_scale.h"
#include "src/world/world.h"
#include "volume/media/media_set.h"
#include "volume/rte/settings.h"

namespace lvox {

struct SegmentPlan {
  rte::Method method = rte::Method::kGaussKronrod;
  rte::SolveSettings<float> settings;
  // Where integration may stop: the segment's end, or earlier where the transmittance from
  // its start is provably below 1e-7 (homogeneous media, auto only).
  float end = kInf;
};

class AutoSolver {
 public:
  // The methods auto picks from (the sweep's study chose them; docs/results.md).
  static constexpr rte::Method kHomogeneousMethod = rte::Method::kGaussKronrod;
  static constexpr rte::Method kHeterogeneousMethod = rte::Method::kRk4;
  static constexpr rte::Method kShadowMethod = rte::Method::kRk4;

  // `scales` and `lengths` outlive the solver.
  AutoSolver(const std::vector<Light>& lights, const MediaSet& media, const MediumScales& scales,
             const StepLengths& lengths, const rte::SolveSettings<float>& base);

  // A camera-ray segment [t0, t1] inside one merged medium interval (emission and
  // in-scattering as the source).
  SegmentPlan radiance(const Ray& ray, float t0, float t1, float jitter) const;
  // A shadow-ray segment through heterogeneous media (transmittance only).
  SegmentPlan transmittance(const Ray& ray, float t0, float t1) const;

 private:
  struct Spot {
    Vec3 apex, axis;
    float cosOuter, cosInner, tanOuter;
  };
  struct PointSource {
    Vec3 position;
    float intensity;  // max channel, for choosing the brightest one seen from a ray
  };

  // What the media that may be non-zero on [t0, t1] are, gathered in one pass.
  struct SegmentMedia {
    bool homogeneous = true;
    bool sourceMayVary = false;    // something scatters (or emits through a grid)
    float smallestExtinction = 0;  // min sigma_t of homogeneous media; 0 if any other
    float extinctionBound = 0;     // sum of the media's majorants: sigma_t <= it
    float step = kInf;             // smallest of the media's own steps (MediumScales)
    float shadowScale = kInf;      // smallest MediumScales::shadowScale
  };
  SegmentMedia mediaOn(const Ray& ray, float t0, float t1) const;
  // Breakpoints in (t0, t1): media box faces and spot cone crossings; and the cap on the
  // step from the spot beams the segment crosses (infinity when it crosses none).
  float addLightStructure(const Ray& ray, float t0, float t1, std::vector<float>& breaks) const;
  void addMediumFaces(const Ray& ray, float t0, float t1, std::vector<float>& breaks) const;

  // Heterogeneous media: RK4 at the media's own step and optical depth per step, both
  // scaled by (tolerance / 1e-3)^(1/4).
  void setRelativeSteps(rte::SolveSettings<float>& s, float mediumStep) const;

  const MediaSet& media_;
  const MediumScales& scales_;
  const StepLengths& lengths_;
  rte::SolveSettings<float> base_;
  std::vector<Spot> spots_;
  std::vector<PointSource> pointSources_;  // point and spot lights
};

// Where the ray crosses the cone {x : dot(x - apex, axis) = |x - apex| cosAngle} in front
// of the apex, for t in (t0, t1); appended to `out` unsorted.
void coneCrossings(const Ray& ray, const Vec3& apex, const Vec3& axis, float cosAngle, float t0,
                   float t1, std::vector<float>& out);

}  // namespace lvox
