#pragma once
// The constant environment's light arriving at points in the media, as order-2 spherical
// harmonics (src/core/spherical_harmonics.h) on a regular grid over the media: direct
// mode's in-scatter of the environment then costs a lookup and a
// phase convolution (Funk-Hecke) instead of a random direction and a shadow ray at every
// medium evaluation, and carries no noise.
//
// Each node solves shadow rays in a fixed set of directions (a spherical Fibonacci
// lattice), through the media and against the surfaces, and projects
// L_env T(x, w) onto the harmonics. Between nodes the mean (the first coefficient) is
// interpolated in its logarithm and the others relative to it, trilinearly (nodes inside
// surfaces, which no direction leaves, are left out): transmittance
// falls exponentially, and interpolating it linearly overestimated the light inside a
// cloud (+1.35 % against +0.18 % on the test's blob at 6 cells). What it costs in error
// (the lattice's quadrature, three
// bands, surfaces' shadows interpolated across a cell) against exact shadow rays:
// docs/results.md, "Shadow transmittance cache". Environment maps are not cached (a sun in
// the map would fall between the directions): their samples keep their shadow rays.
#include <functional>
#include <vector>

#include "src/core/math.h"
#include "src/core/spherical_harmonics.h"
#include "src/render/node_grid.h"

namespace lvox {

class EnvironmentCache {
 public:
  // Transmittance of the media and the surfaces along a shadow ray; called from TBB
  // workers (thread-safe and deterministic).
  using Transmittance = std::function<RGB(const Ray&)>;

  // Grids over `bounds` with `resolution` cells along its longest side (cubic cells), each
  // node projecting `radiance` x T over `directions` directions.
  EnvironmentCache(const RGB& radiance, const Bounds3& bounds, int resolution, int directions,
                   const Transmittance& transmittance);

  bool covers(const Vec3& x) const { return grid_.contains(x); }
  // The harmonics of the light arriving at x: c_k = (1 / 4 pi) integral L T Yhat_k dw
  // (kShCoefficients of them).
  void lookup(const Vec3& x, RGB* coefficients) const;
  size_t nodes() const { return grid_.nodes(); }
  size_t memoryBytes() const { return coefficients_.size() * sizeof(RGB); }

  // Direction j of n on the spherical Fibonacci lattice (equal areas of 4 pi / n).
  static Vec3 latticeDirection(int j, int n);

 private:
  NodeGrid grid_;
  std::vector<RGB> coefficients_;  // kShCoefficients per node
};

}  // namespace lvox
