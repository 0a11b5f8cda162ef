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
//
// A surface between a point and a node (a wall or ceiling that the media pass through)
// leaves that node out as well: its light is the other side's. Nodes with a surface within
// one cell are marked when the cache is built (the segments to the corners of the box of
// their neighbours), and a lookup tests only those.
#include <cstdint>
#include <functional>
#include <vector>

#include "src/core/math.h"
#include "src/core/spherical_harmonics.h"
#include "src/geometry/ray_tracer.h"
#include "src/render/node_grid.h"

namespace lvox {

class EnvironmentCache {
 public:
  // Transmittance of the media and the surfaces along a shadow ray; called from TBB
  // workers (thread-safe and deterministic).
  using Transmittance = std::function<RGB(const Ray&)>;

  // Grids over `bounds` with `resolution` cells along its longest side (cubic cells), each
  // node projecting `radiance` x T over `directions` directions. With `surfaces`, lookups
  // leave out nodes that a surface hides (see above); it must outlive the cache.
  EnvironmentCache(const RGB& radiance, const Bounds3& bounds, int resolution, int directions,
                   const Transmittance& transmittance, const RayTracer* surfaces = nullptr);

  bool covers(const Vec3& x) const { return grid_.contains(x); }
  // The harmonics of the light arriving at x: c_k = (1 / 4 pi) integral L T Yhat_k dw
  // (kShCoefficients of them).
  void lookup(const Vec3& x, RGB* coefficients) const;
  size_t nodes() const { return grid_.nodes(); }
  size_t memoryBytes() const { return coefficients_.size() * sizeof(RGB) + nearSurface_.size(); }
  // Nodes with a surface within one cell (0 without `surfaces`).
  size_t nodesNearSurfaces() const;

  // Direction j of n on the spherical Fibonacci lattice (equal areas of 4 pi / n).
  static Vec3 latticeDirection(int j, int n);

 private:
  // Whether a surface lies between x and a node, or through the node.
  bool hidden(const Vec3& x, const Vec3& node) const;
  NodeGrid grid_;
  std::vector<RGB> coefficients_;  // kShCoefficients per node
  const RayTracer* surfaces_ = nullptr;
  std::vector<uint8_t> nearSurface_;  // per node, with `surfaces`
};

}  // namespace lvox
