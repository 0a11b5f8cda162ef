#include "src/render/auto_solver.h"

#include <algorithm>
#include <cmath>

#include "volume/rte/change_of_variable.h"

namespace lvox {
namespace {

constexpr float kDegrees = kPi / 180.0f;

// Kronrod-15's widest gap between adjacent nodes (about the centre), per unit panel length.
constexpr float kKronrodLargestGap = 0.104f;
// Optical depth after which the rest of a segment is invisible (T < 1e-7).
constexpr float kOpaqueDepth = 16.2f;
// The optical depth of auto's first Gauss-Kronrod panels at most: below the 4 at which
// gaussKronrodRule splits a panel whatever its error estimate.
constexpr float kPanelDepth = 3.9f;
// The tolerance at which heterogeneous media take the steps below (the default).
constexpr float kReferenceTolerance = 1e-3f;
// RK4 steps through heterogeneous media at the reference tolerance: the medium's own step
// (MediumScales: 1.2 steps per narrowest bump), and at most 0.6 optical depths per step,
// split locally where the medium is denser (SolveSettings::depthPerStep; RK4's error on
// exp(-tau) is tau^5 / 120 per step).
constexpr float kDepthPerStep = 0.6f;
// Steps across a spot beam's width at the ray.
constexpr float kStepsPerBeam = 4.0f;

}  // namespace

void coneCrossings(const Ray& ray, const Vec3& apex, const Vec3& axis, float cosAngle, float t0,
                   float t1, std::vector<float>& out) {
  // (dot(v + t d, A))^2 = c^2 |v + t d|^2 with v = o - apex: a quadratic in t.
  const Vec3 v = ray.origin - apex;
  const double dA = dot(ray.dir, axis), vA = dot(v, axis), c2 = double(cosAngle) * cosAngle;
  const double a = dA * dA - c2;
  const double b = 2.0 * (dA * vA - c2 * dot(ray.dir, v));
  const double c = vA * vA - c2 * dot(v, v);
  double roots[2];
  int n = 0;
  if (std::abs(a) < 1e-12) {
    if (std::abs(b) > 1e-12) roots[n++] = -c / b;
  } else {
    const double disc = b * b - 4.0 * a * c;
    if (disc < 0.0) return;
    // The numerically stable pair (no cancellation between -b and sqrt(disc)).
    const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
    roots[n++] = q / a;
    if (q != 0.0) roots[n++] = c / q;
  }
  for (int i = 0; i < n; ++i) {
    const float t = static_cast<float>(roots[i]);
    if (!(t > t0 && t < t1)) continue;
    if (dot(ray.at(t) - apex, axis) <= 0.0f) continue;  // the mirror cone behind the apex
    out.push_back(t);
  }
}

AutoSolver::AutoSolver(const std::vector<Light>& lights, const MediaSet& media,
                       const MediumScales& scales, const StepLengths& lengths,
                       const rte::SolveSettings<float>& base)
    : media_(media), scales_(scales), lengths_(lengths), base_(base) {
  for (const Light& l : lights) {
    if (l.type != LightType::Point && l.type != LightType::Spot) continue;
    pointSources_.push_back({l.position, maxComponent(l.intensity)});
    if (l.type != LightType::Spot) continue;
    const float inner = std::max(0.0f, l.coneDeg - l.falloffDeg);
    spots_.push_back({l.position, l.direction, std::cos(l.coneDeg * kDegrees),
                      inner > 0.0f ? std::cos(inner * kDegrees) : 2.0f,
                      std::tan(std::min(l.coneDeg, 89.0f) * kDegrees)});
  }
}

AutoSolver::SegmentMedia AutoSolver::mediaOn(const Ray& ray, float t0, float t1) const {
  thread_local std::vector<std::pair<float, float>> spans;
  SegmentMedia on;
  float sigma = kInf;
  for (size_t i = 0; i < media_.size(); ++i) {
    spans.clear();
    media_[i].intervals(ray, t0, t1, spans);
    if (spans.empty()) continue;
    const Medium& m = media_[i];
    on.homogeneous = on.homogeneous && m.homogeneous();
    on.sourceMayVary = on.sourceMayVary || !isBlack(m.sigmaS) || m.emissionGrid != nullptr ||
                       m.temperatureGrid != nullptr;
    const RGB t = m.homogeneous() ? m.majorant() : RGB(0.0f);
    sigma = std::min({sigma, t.x, t.y, t.z});
    on.extinctionBound += maxComponent(m.majorant());
    on.step = std::min(on.step, scales_.step(i));
    on.shadowScale = std::min(on.shadowScale, scales_.shadowScale(i));
  }
  // Every point of a merged medium interval lies in at least one of these media.
  on.smallestExtinction = std::isinf(sigma) ? 0.0f : sigma;
  if (std::isinf(on.step)) on.step = MediumScales::segmentStep(t0, t1);  // no medium found
  if (std::isinf(on.shadowScale)) on.shadowScale = on.step;
  return on;
}

void AutoSolver::addMediumFaces(const Ray& ray, float t0, float t1,
                                std::vector<float>& breaks) const {
  for (const Medium& m : media_.media()) {
    float a, b;
    Ray r = ray;
    r.tmin = -kInf;
    r.tmax = kInf;
    if (!m.bounds.intersect(r, a, b)) continue;
    for (float t : {a, b})
      if (t > t0 && t < t1) breaks.push_back(t);
  }
}

float AutoSolver::addLightStructure(const Ray& ray, float t0, float t1,
                                    std::vector<float>& breaks) const {
  float cap = kInf;
  for (const Spot& s : spots_) {
    const size_t before = breaks.size();
    coneCrossings(ray, s.apex, s.axis, s.cosOuter, t0, t1, breaks);
    if (s.cosInner <= 1.0f) coneCrossings(ray, s.apex, s.axis, s.cosInner, t0, t1, breaks);
    // The beam's width where the segment passes closest to the apex (or inside the beam
    // when the segment does not cross its edge, e.g. it starts and ends inside it).
    const float tc = std::clamp(dot(s.apex - ray.origin, ray.dir), t0, t1);
    const Vec3 toPoint = ray.at(tc) - s.apex;
    const float along = dot(toPoint, s.axis);
    const bool inside = along > 0.0f && along >= length(toPoint) * s.cosOuter;
    if (breaks.size() == before && !inside) continue;
    const float width = 2.0f * std::max(along, 0.0f) * s.tanOuter;
    if (width > 0.0f) cap = std::min(cap, width / kStepsPerBeam);
  }
  return cap;
}

SegmentPlan AutoSolver::radiance(const Ray& ray, float t0, float t1, float jitter) const {
  SegmentPlan plan;
  rte::SolveSettings<float>& s = plan.settings;
  s = base_;
  s.jitter = jitter;
  addMediumFaces(ray, t0, t1, s.breakpoints);
  const float beamCap = addLightStructure(ray, t0, t1, s.breakpoints);
  std::sort(s.breakpoints.begin(), s.breakpoints.end());
  plan.end = t1;
  const SegmentMedia on = mediaOn(ray, t0, t1);
  if (on.homogeneous && !on.sourceMayVary) {
    // Absorption and emission only: sigma_t and the source are constant between the box
    // faces, and left-point marching integrates a constant piece exactly,
    // Q += T J (1 - exp(-sigma h)) / sigma: one step per piece.
    plan.method = rte::Method::kRectangle;
    s.step = t1 - t0;
    s.jitter = 0.0f;
    return plan;
  }
  if (on.homogeneous) {
    plan.method = kHomogeneousMethod;
    // Beyond T < 1e-7 (tau > 16.2) nothing visible is left to integrate; in a medium so
    // thick that this depth is below float resolution at t0 (sigma_t 1e8 four units from
    // the camera), one ulp.
    if (on.smallestExtinction > 0.0f)
      t1 = plan.end =
          std::min(t1, std::max(t0 + kOpaqueDepth / on.smallestExtinction, std::nextafter(t0, t1)));
    // No two evaluations further apart than the scene's step (without one: the scale of the
    // shadows cast into the media, MediumScales::shadowScale) or a quarter beam where the
    // map is densest: a panel may span that gap over Kronrod's widest node gap.
    lengths_.apply(on.shadowScale, s);
    const float cap = std::min({s.step, s.maxStep, beamCap}) / kKronrodLargestGap;
    s.step = cap;
    // Flatten the largest factor of the integrand: the brightest point source's 1/r^2
    // (by intensity over squared distance to the ray).
    float best = 0.0f;
    for (const PointSource& p : pointSources_) {
      const Vec3 toLight = p.position - ray.origin;
      const float delta = dot(toLight, ray.dir);
      const float h = std::max(1e-4f, length(toLight - ray.dir * delta));
      const float peak = p.intensity / (h * h);
      if (peak <= best) continue;
      best = peak;
      s.sampling = rte::Sampling::kEquiangular;
      s.delta = delta;
      s.h = h;
    }
    // Without a point light the attenuation is the only varying factor, and sigma_t is
    // constant: Gauss-Kronrod in t (thick panels split) costs less than under the distance
    // map, whose mapped sigma_t ~ 1 / (1 - s) its node interpolant represents poorly.
    const float densest = s.sampling == rte::Sampling::kEquiangular ? 1.0f / s.h : 1.0f;
    // First panels equal in the equiangular variable (in t without a point light), none
    // longer than `cap` where that variable is densest: they grow with the distance to the
    // light, and Gauss-Kronrod's error estimate splits them where the tolerance asks.
    const auto map = rte::VariableChange<float>::make(s.sampling, t0, s.sigmaRef, s.delta, s.h);
    const float panels = std::ceil((map.toS(t1) - map.toS(t0)) / (densest * cap) - 1e-4f);
    // No first panel optically thicker than Gauss-Kronrod accepts (tau <= 4,
    // gaussKronrodRule): each rejection on the way down from a thicker one costs 15
    // evaluations (panels are equal in t without a point light, where this bound is exact).
    const float thick = std::ceil((t1 - t0) * on.extinctionBound / kPanelDepth);
    const float count =
        std::max(std::clamp(panels, 1.0f, std::max(1.0f, std::ceil((t1 - t0) / cap))), thick);
    s.step = (t1 - t0) / count;
    // One panel covers the segment: a jittered start would only split it in two (its nodes
    // are placed relative to the segment's ends, which move smoothly from pixel to pixel).
    if (count == 1.0f) s.jitter = 0.0f;
    return plan;
  }
  plan.method = kHeterogeneousMethod;
  setRelativeSteps(s, on.step);
  s.step = std::max(s.minStep, std::min(s.step, beamCap));
  return plan;
}

void AutoSolver::setRelativeSteps(rte::SolveSettings<float>& s, float mediumStep) const {
  lengths_.apply(mediumStep, s);  // min_step
  // RK4's error goes as h^4: a tolerance 10x tighter costs 10^(1/4) more steps.
  const float scale = std::pow(base_.tolerance / kReferenceTolerance, 0.25f);
  s.step = std::max(s.minStep, mediumStep * scale);
  s.depthPerStep = kDepthPerStep * scale;
}

SegmentPlan AutoSolver::transmittance(const Ray& ray, float t0, float t1) const {
  SegmentPlan plan;
  plan.method = kShadowMethod;
  rte::SolveSettings<float>& s = plan.settings;
  s = base_;
  s.jitter = 0.5f;
  setRelativeSteps(s, mediaOn(ray, t0, t1).step);
  return plan;
}

}  // namespace lvox
