#include "src/render/medium_scale.h"

#include <algorithm>
#include <cmath>

namespace lvox {
namespace {

// 1.2 steps per narrowest density bump: RK4 at this step is on the sweep study's front in
// the noise field and the atrium's plume (docs/results.md).
constexpr float kStepsPerFeature = 1.2f;
// Optical depth per step where the medium has no bump: RK4's error on exp(-tau) is
// tau^5 / 120 per step, 6.5e-4 at 0.6.
constexpr float kDepthPerStep = 0.6f;
// Shadows of surfaces resolved to 1/128 of the surfaces' extent (0.13 units across the
// 17-unit hard-case rooms, whose scenes give 0.1).
constexpr float kSurfaceShadowDivisions = 128.0f;
// A homogeneous medium is stepped at least 16 times across its box.
constexpr float kBoxDivisions = 16.0f;

float smallestVoxel(const SparseGrid& g) {
  const Transform& m = g.indexToWorld();
  float s = kInf;
  for (const Vec3& axis : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)})
    s = std::min(s, length(m.vector(axis)));
  return s;
}

// The width of the narrowest bump a medium's density can have.
float narrowestBump(const Medium& m) {
  switch (m.type) {
    case MediumType::Homogeneous:
      return kInf;
    case MediumType::Vdb:
      // A one-voxel spike spreads over 1, 2 or 4 voxels under nearest, trilinear and
      // tricubic interpolation.
      if (!m.density) return kInf;
      return smallestVoxel(*m.density) * (m.interpolation == Interpolation::Nearest     ? 1.0f
                                          : m.interpolation == Interpolation::Trilinear ? 2.0f
                                                                                        : 4.0f);
    case MediumType::Procedural:
      switch (m.procedural) {
        case ProceduralKind::Noise:
          return 0.5f / std::max(m.frequency, 1e-6f);  // a bump is half a period wide
        case ProceduralKind::GaussianBlob:
          return m.radius;
        default:
          return kInf;  // constant or linear: nothing to step over
      }
  }
  return kInf;
}

}  // namespace

MediumScales::MediumScales(const Bounds3& surfaces, const MediaSet& media) : media_(media) {
  if (!surfaces.empty()) {
    const float extent = length(surfaces.diagonal());
    if (extent > 0.0f) shadowScale_ = extent / kSurfaceShadowDivisions;
  }
  for (const Medium& m : media.media()) {
    featureSize_.push_back(narrowestBump(m));
    boxScale_.push_back(length(m.bounds.diagonal()) / kBoxDivisions);
    if (std::isfinite(featureSize_.back()))
      shadowScale_ = std::min(shadowScale_, featureSize_.back() / kStepsPerFeature);
  }
  for (size_t i = 0; i < featureSize_.size(); ++i) {
    if (std::isfinite(featureSize_[i])) {
      step_.push_back(featureSize_[i] / kStepsPerFeature);
      continue;
    }
    const float sigma = maxComponent(media[i].majorant());
    const float optical = sigma > 0.0f ? kDepthPerStep / sigma : kInf;
    step_.push_back(std::min(optical, shadowScale(i)));
  }
}

float MediumScales::step(const Ray& ray, float t0, float t1) const {
  thread_local std::vector<std::pair<float, float>> spans;
  float s = kInf;
  for (size_t i = 0; i < media_.size(); ++i) {
    if (step_[i] >= s) continue;
    spans.clear();
    media_[i].intervals(ray, t0, t1, spans);
    if (!spans.empty()) s = step_[i];
  }
  return std::isinf(s) ? segmentStep(t0, t1) : s;
}

void StepLengths::apply(float natural, rte::SolveSettings<float>& s) const {
  const float base = step ? *step : natural;
  s.step = step ? *step : natural * scale;
  // As the absolute defaults were to the old default step of 0.1: 1e-4 and 1.
  s.minStep = minStep ? *minStep : base * 1e-3f;
  s.maxStep = maxStep ? *maxStep : base * 10.0f;
}

}  // namespace lvox
