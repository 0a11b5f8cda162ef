#pragma once
// All media of a scene. Where media overlap their coefficients add (and their sources);
// the in-scattering of each medium keeps its own phase function.
#include <string>
#include <vector>

#include "src/core/memory_budget.h"
#include "volume/media/medium.h"

namespace lvox {

class MediaSet {
 public:
  MediaSet() = default;
  // Builds every described medium (reading VDB grids, sampled with `interpolation`);
  // problems that do not stop the render (negative voxels clamped, empty grids) are
  // appended to `warnings`.
  // With `budget`, each grid's tree is reserved in it before it is read (loadVdbGrid), so
  // a grid larger than the budget stops the render before OpenVDB allocates it.
  static MediaSet build(const std::vector<MediumDesc>& media, Interpolation interpolation,
                        std::vector<std::string>& warnings, MemoryBudget* budget = nullptr);

  bool empty() const { return media_.empty(); }
  size_t size() const { return media_.size(); }
  const Medium& operator[](size_t i) const { return media_[i]; }
  const std::vector<Medium>& media() const { return media_; }
  bool allHomogeneous() const;

  // Sum of the coefficients of every medium at p.
  MediumCoefficients at(const Vec3& p) const;
  // Sum of sigma_t of the heterogeneous media at p (homogeneous ones are done analytically).
  // `reduced`: of sigma_t - f sigma_s, each medium's extinction without its phase's forward
  // peak f (PhaseFunction::truncated; pcb's anisotropic lvoxels, docs/pcb.md).
  RGB heterogeneousSigmaT(const Vec3& p, bool reduced = false) const;
  bool anyHeterogeneous() const { return !allHomogeneous(); }
  bool anyEmissive() const {
    for (const Medium& m : media_)
      if (m.emits()) return true;
    return false;
  }
  // Optical depth of the homogeneous media along [tmin, tmax] of the ray (exact).
  RGB homogeneousOpticalDepth(const Ray& ray, float tmin, float tmax, bool reduced = false) const;
  // Sorted, merged t-intervals in [tmin, tmax] where a heterogeneous medium may be non-zero.
  void heterogeneousIntervals(const Ray& ray, float tmin, float tmax,
                              std::vector<std::pair<float, float>>& out) const;
  // Sorted, merged t-intervals in [tmin, tmax] where any medium may be non-zero.
  void intervals(const Ray& ray, float tmin, float tmax,
                 std::vector<std::pair<float, float>>& out) const;
  Bounds3 bounds() const;
  size_t memoryBytes() const;

  void add(Medium m) { media_.push_back(std::move(m)); }

 private:
  std::vector<Medium> media_;
};

// At most this many media are evaluated per point (no allocation in the hot path).
inline constexpr size_t kMaxMedia = 8;

// Sorts and merges overlapping or touching intervals in place.
void mergeIntervals(std::vector<std::pair<float, float>>& intervals);

}  // namespace lvox
