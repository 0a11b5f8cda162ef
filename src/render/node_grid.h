#pragma once
// A regular grid of nodes over a box, `resolution` cells along its longest side (cubic
// cells), with trilinear weights: the geometry the shadow caches share
// (src/render/transmittance_cache.h, src/render/environment_cache.h).
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "src/core/math.h"

namespace lvox {

class NodeGrid {
 public:
  NodeGrid() = default;
  NodeGrid(const Bounds3& bounds, int resolution) : bounds_(bounds) {
    if (bounds.empty() || resolution < 1) return;
    const Vec3 extent = bounds.diagonal();
    const float side = std::max({extent.x, extent.y, extent.z}) / static_cast<float>(resolution);
    for (int a = 0; a < 3; ++a) {
      n_[a] = std::max(2, static_cast<int>(std::ceil(extent[a] / side)) + 1);
      cell_[a] = extent[a] > 0.0f ? extent[a] / static_cast<float>(n_[a] - 1) : 1.0f;
    }
  }

  const Bounds3& bounds() const { return bounds_; }
  bool contains(const Vec3& x) const { return bounds_.contains(x); }
  size_t nodes() const { return static_cast<size_t>(n_[0]) * n_[1] * n_[2]; }
  const Vec3& spacing() const { return cell_; }  // between neighbouring nodes, per axis

  // Where node i is (x fastest, then y, then z).
  Vec3 position(size_t i) const {
    const auto nx = static_cast<size_t>(n_[0]), ny = static_cast<size_t>(n_[1]);
    return bounds_.lo +
           mul(cell_, Vec3(static_cast<float>(i % nx), static_cast<float>((i / nx) % ny),
                           static_cast<float>(i / (nx * ny))));
  }

  // f(node, weight) for the corners of x's cell with a non-zero trilinear weight (x is
  // clamped into the grid).
  template <class F>
  void forEachCorner(const Vec3& x, F&& f) const {
    float t[3];
    int i[3];
    for (int a = 0; a < 3; ++a) {
      const float u =
          std::clamp((x[a] - bounds_.lo[a]) / cell_[a], 0.0f, static_cast<float>(n_[a] - 1));
      i[a] = std::min(static_cast<int>(u), n_[a] - 2);
      t[a] = u - static_cast<float>(i[a]);
    }
    for (int corner = 0; corner < 8; ++corner) {
      const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
      const float w =
          (dx ? t[0] : 1.0f - t[0]) * (dy ? t[1] : 1.0f - t[1]) * (dz ? t[2] : 1.0f - t[2]);
      if (w == 0.0f) continue;
      f((static_cast<size_t>(i[2] + dz) * static_cast<size_t>(n_[1]) +
         static_cast<size_t>(i[1] + dy)) *
                static_cast<size_t>(n_[0]) +
            static_cast<size_t>(i[0] + dx),
        w);
    }
  }

 private:
  Bounds3 bounds_;
  int n_[3] = {0, 0, 0};  // nodes per axis
  Vec3 cell_;             // node spacing
};

}  // namespace lvox
