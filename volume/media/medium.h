#pragma once
// One participating medium: a homogeneous box, a procedural density in a box, or an
// OpenVDB density grid. A plain struct with a switch on the kind per lookup (no virtual
// call per sample); grids are shared, immutable and thread-safe to read (sparse: the
// OpenVDB tree as read, see sparse_grid.h).
//
// Coefficients per unit length: sigma_t = sigma_a + sigma_s. VDB media: sigma_t =
// density_scale * density, sigma_s = albedo * sigma_t. Box media: density (1, or the
// procedural field) times the given sigma_a and sigma_s. The emission source term is
// sigma_a * Le (times the emission grid where there is one), plus sigma_a times the
// blackbody radiance of the temperature grid where there is one (Kirchhoff's law).
#include <memory>
#include <utility>
#include <vector>

#include "volume/media/blackbody.h"
#include "volume/media/medium_desc.h"
#include "volume/media/sparse_grid.h"
#include "volume/phase.h"

namespace lvox {

struct MediumCoefficients {
  RGB sigmaA{0.0f};
  RGB sigmaS{0.0f};
  RGB source{0.0f};  // sigma_a * Le
  RGB sigmaT() const { return sigmaA + sigmaS; }
};

struct Medium {
  MediumType type = MediumType::Homogeneous;
  ProceduralKind procedural = ProceduralKind::Constant;
  Bounds3 bounds;                  // world space; no medium outside
  RGB sigmaA{0.0f}, sigmaS{0.0f};  // box media (per unit density)
  RGB emission{0.0f};              // Le
  PhaseFunction phase;
  // procedural parameters (see MediumDesc)
  Vec3 gradient, center;
  float radius = 1.0f, frequency = 1.0f;
  // grids
  std::shared_ptr<const SparseGrid> density, emissionGrid;
  // The majorant granularity tracking uses in this medium (the cheapest for its grid and
  // density scale, see SparseGrid::cheapestMajorantLevel).
  MajorantLevel majorantLevel = MajorantLevel::kBlock;
  // Blackbody emission: source += sigma_a x blackbodyIntensity x blackbody(temperature x
  // the grid's value), tabulated up to the grid's hottest voxel.
  std::shared_ptr<const SparseGrid> temperatureGrid;
  std::shared_ptr<const BlackbodyTable> blackbody;
  float temperature = 1000.0f;
  float blackbodyIntensity = 1.0f;
  float densityScale = 1.0f;
  RGB albedo{0.0f};
  Interpolation interpolation = Interpolation::Trilinear;

  bool homogeneous() const { return type == MediumType::Homogeneous; }
  // Whether the medium may have a non-zero emission source anywhere.
  bool emits() const { return !isBlack(emission) || temperatureGrid != nullptr; }
  float densityAt(const Vec3& p) const;
  MediumCoefficients at(const Vec3& p) const;
  // An upper bound of sigma_t anywhere (per channel).
  RGB majorant() const;
  // Sorted t-intervals of the ray in [tmin, tmax] where this medium may be non-zero.
  void intervals(const Ray& ray, float tmin, float tmax,
                 std::vector<std::pair<float, float>>& out) const;
  size_t memoryBytes() const;
};

}  // namespace lvox
