#pragma once
// Surfels buried in geometry. Modelled scenes let pieces overlap (a slab pushed into a
// wall, a shaft into its plinth) so that no light leaks through cracks; the part of a
// face inside another solid gets surfels too. They receive no light, yet their disks
// stick out of the solid by up to a radius and gather rays from outside hit them: dark
// patches all along every joint. A surfel is buried when every short probe ray from
// either side hits geometry within `reach`: neither side can be seen from open space.
#include <cstddef>
#include <cstdint>

#include "pointcloud/surfels.h"
#include "src/geometry/ray_tracer.h"

namespace lvox {

struct BuriedSurfelSettings {
  float reach = 0.0f;  // scene units, > 0: e.g. twice the surfel spacing
  int raysPerSide = 16;
  uint64_t seed = 1;
};

// Removes the buried surfels (order of the others kept); returns how many were removed.
size_t removeBuriedSurfels(SurfelSet& surfels, const RayTracer& tracer,
                           const BuriedSurfelSettings& settings);

}  // namespace lvox
