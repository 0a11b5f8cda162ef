#pragma once
// Transmittance from points in the media to each point, spot and directional light, solved
// once per node of a regular grid over the media and interpolated trilinearly in its
// logarithm (a deep shadow map in world space): direct mode's in-scatter samples then cost
// a lookup instead of a shadow ray through the media. Surfaces still occlude by their own (Embree)
// ray; only the media's part is cached, which is exact to multiply: an occluder between the point
// and the light makes the product 0 whatever the media did. Error and cost against exact
// shadow rays: docs/results.md, "Shadow transmittance cache".
#include <cstdint>
#include <functional>
#include <vector>

#include "src/core/math.h"
#include "src/render/node_grid.h"
#include "src/world/world.h"

namespace lvox {

class TransmittanceCache {
 public:
  // T(ray) of the media along a shadow ray; called once per node and light, from TBB
  // workers (it must be thread-safe and deterministic).
  using Transmittance = std::function<RGB(const Ray&)>;

  // Grids over `bounds` with `resolution` cells along its longest side (cubic cells), one
  // per light of `lights` that is not an environment (others get none).
  TransmittanceCache(const std::vector<Light>& lights, const Bounds3& bounds, int resolution,
                     const Transmittance& transmittance);

  bool covers(const Vec3& x) const { return grid_.contains(x); }
  // Trilinear T from x towards lights[light]; x must be covered.
  RGB lookup(size_t light, const Vec3& x) const;
  bool cached(size_t light) const { return light < grids_.size() && !grids_[light].empty(); }
  size_t nodes() const { return grid_.nodes(); }
  size_t memoryBytes() const;

  // The shadow ray from x towards `light` (distance shortened as direct mode's rays are).
  static Ray shadowRay(const Light& light, const Vec3& x);
  // The nodes a cache over `bounds` at `resolution` has (per light).
  static size_t nodeCount(const Bounds3& bounds, int resolution);

 private:
  NodeGrid grid_;
  std::vector<std::vector<RGB>> grids_;
};

}  // namespace lvox
