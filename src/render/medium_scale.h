#pragma once
// The lengths over which the media, and the light inside them, can change: what a ray
// segment's steps are relative to when the scene gives none (docs/solvers.md, "Steps
// relative to the medium"). A scene modelled in centimetres then steps as the same scene in
// metres does.
//   - A heterogeneous medium: its narrowest density bump (1, 2 or 4 voxels under nearest,
//     trilinear and tricubic interpolation; half a noise period; a Gaussian blob's radius),
//     1.2 steps per bump.
//   - A homogeneous medium (or a constant or linear one) has no length of its own but its
//     mean free path; the light in it has the shadows cast into it. Its step is the
//     smallest of 0.6 optical depths (at its majorant), the shadows' scale and a sixteenth
//     of its box's diagonal. Shadows come from surfaces (1/128 of the surfaces' bounding
//     diagonal) and from heterogeneous media (their own step). Spot beams are auto's
//     business (it caps steps inside them, src/render/auto_solver.h).
#include <algorithm>
#include <limits>
#include <optional>
#include <vector>

#include "src/core/math.h"
#include "volume/media/media_set.h"
#include "volume/rte/settings.h"

namespace lvox {

class MediumScales {
 public:
  // `surfaces`: the bounds of every surface that can cast a shadow (empty if none).
  MediumScales(const Bounds3& surfaces, const MediaSet& media);

  // The narrowest density bump of medium `i` (infinity for constant and linear media).
  float featureSize(size_t i) const { return featureSize_[i]; }
  // Medium `i`'s own step, as in the header comment.
  float step(size_t i) const { return step_[i]; }
  // The smallest step of the media that may be non-zero on [t0, t1]; segmentStep(t0, t1)
  // when none is found on it.
  float step(const Ray& ray, float t0, float t1) const;
  // The step of a segment on which no medium is found: the whole segment. A sliver at a
  // medium's edge (a shadow ray's interval of 2.4e-7 units in Sponza's smoke) can be one.
  static float segmentStep(float t0, float t1) {
    return std::max(t1 - t0, std::numeric_limits<float>::min());
  }
  // The scale of the shadows cast into homogeneous media, capped by a sixteenth of medium
  // `i`'s box diagonal: how far apart the nodes of a quadrature may be before they can miss
  // a shadow (the attenuation itself is left to its error estimate).
  float shadowScale(size_t i) const { return std::min(shadowScale_, boxScale_[i]); }

 private:
  const MediaSet& media_;
  std::vector<float> featureSize_, step_, boxScale_;
  float shadowScale_ = kInf;
};

// The scene's step settings: lengths in scene units where it gives them, else relative. The
// step is `scale` times a segment's natural step (MediumScales::step) when the scene gives
// none; min_step and max_step are a thousandth and ten times the scene's step or, without
// one, the natural step.
struct StepLengths {
  std::optional<float> step, minStep, maxStep;
  float scale = 1.0f;

  bool relative() const { return !step; }
  // Sets s.step, s.minStep and s.maxStep for a segment whose natural step is `natural`
  // (finite and > 0).
  void apply(float natural, rte::SolveSettings<float>& s) const;
};

}  // namespace lvox
