#include "volume/media/majorant_tracker.h"

#include <algorithm>
#include <cmath>

#include "src/core/sampling.h"

namespace lvox {
namespace {

void mediumSegments(const Medium& m, const Ray& ray, float tmin, float tmax, bool useGrid,
                    std::vector<MajorantSpan>& out) {
  if (m.type == MediumType::Vdb && useGrid) {
    const size_t first = out.size();
    m.density->majorantSpans(ray, tmin, tmax, m.majorantLevel, out);
    for (size_t i = first; i < out.size(); ++i) out[i].majorant *= m.densityScale;
    return;
  }
  const float maj = maxComponent(m.majorant());
  if (maj <= 0.0f) return;
  std::vector<std::pair<float, float>> spans;
  m.intervals(ray, tmin, tmax, spans);
  for (const auto& [a, b] : spans) out.push_back({a, b, maj});
}

}  // namespace

void MajorantTracker::segments(const Ray& ray, float tmin, float tmax, bool heterogeneousOnly,
                               std::vector<MajorantSpan>& out) const {
  out.clear();
  std::vector<MajorantSpan> all;
  size_t contributing = 0;
  for (const Medium& m : media_.media()) {
    if (heterogeneousOnly && m.homogeneous()) continue;
    const size_t before = all.size();
    mediumSegments(m, ray, tmin, tmax, useGrid_, all);
    contributing += all.size() > before ? 1 : 0;
  }
  if (contributing <= 1) {
    out = std::move(all);
    return;
  }
  // Overlapping media: majorants add. Sweep over the segment ends.
  std::vector<std::pair<float, float>> events;  // (t, +-majorant)
  for (const MajorantSpan& s : all) {
    events.emplace_back(s.t0, s.majorant);
    events.emplace_back(s.t1, -s.majorant);
  }
  std::sort(events.begin(), events.end());
  float current = 0.0f;
  for (size_t i = 0; i + 1 < events.size(); ++i) {
    current += events[i].second;
    const float a = events[i].first, b = events[i + 1].first;
    if (b > a && current > 1e-12f) out.push_back({a, b, current});
  }
}

RGB MajorantTracker::transmittance(const Ray& ray, Rng& rng, uint64_t& lookups) const {
  if (media_.empty()) return RGB(1.0f);
  const float tmax = std::isinf(ray.tmax) ? 1e30f : ray.tmax;
  const RGB tau = media_.homogeneousOpticalDepth(ray, ray.tmin, tmax);
  RGB tr(std::exp(-tau.x), std::exp(-tau.y), std::exp(-tau.z));
  if (!media_.anyHeterogeneous()) return tr;
  thread_local std::vector<MajorantSpan> segs;
  segments(ray, ray.tmin, tmax, true, segs);
  forEachTentativeCollision(segs, rng, [&](float t, float majorant) {
    ++lookups;
    tr *= RGB(1.0f) - media_.heterogeneousSigmaT(ray.at(t)) / majorant;
    // Russian roulette on small transmittance keeps the estimator unbiased.
    const float m = maxComponent(tr);
    if (m < 0.1f) {
      if (rng.uniform() >= m / 0.1f) {
        tr = RGB(0.0f);
        return false;
      }
      tr /= m / 0.1f;
    }
    return true;
  });
  return tr;
}

}  // namespace lvox
