#pragma once
// Surfels buried in geometry. Modelled scenes let pieces overlap (a slab pushed into a
// wall, a shaft into its plinth) so that no light leaks through cracks; the part of a
// face inside another solid gets surfels too. They receive no light, yet their disks
// stick out of the solid by up to a radius and gather rays from outside hit them: dark
// patches all along every joint. A surfel is buried when every short probe ray from
// either side hits geometry within `reach`: neither side can be seen from open space.
//
// A surfel with one such side (the inner side of a wall, a column, a box) stays, with that
// side marked in `enclosedSides`: gather rays pass by it. A disk is flat and its surface
// may curve away from it or end at a corner, so the disks of a convex surface stick out
// past it, and a gather ray from the surface itself can meet the inner side of a
// neighbour's disk: on a column, the inside of the shaft, which is black.
//
// The probes cannot tell a solid from a closed room smaller than the reach: the walls of
// such a room look enclosed from inside. A side that `viewpoint` (a point in open space,
// the camera) sees directly is open whatever the probes say, so the room the camera is in
// is always kept; a closed room elsewhere smaller than the reach in every direction is not
// (keep `reach` below room sizes, or 0).
#include <cstddef>
#include <cstdint>
#include <optional>

#include "pointcloud/surfels.h"
#include "src/geometry/ray_tracer.h"

namespace lvox {

struct BuriedSurfelSettings {
  float reach = 0.0f;  // scene units, > 0: e.g. twice the surfel spacing
  int raysPerSide = 16;
  uint64_t seed = 1;
  std::optional<Vec3> viewpoint;  // a point known to be in open space
};

// Marks the enclosed sides of every surfel and removes the surfels enclosed on both sides
// (order of the others kept); returns how many were removed.
size_t removeBuriedSurfels(SurfelSet& surfels, const RayTracer& tracer,
                           const BuriedSurfelSettings& settings);

// Its two halves, for a set probed in parts (one per rank, docs/cluster.md): marks the
// enclosed sides of surfels [begin, end) only (each surfel's probes are numbered by its
// index, so parts give what the whole gives), ...
void markEnclosedSides(SurfelSet& surfels, const RayTracer& tracer,
                       const BuriedSurfelSettings& settings, size_t begin, size_t end);
// ... and, once every surfel is marked, removes those enclosed on both sides (order kept);
// returns how many.
size_t removeEnclosedSurfels(SurfelSet& surfels);

}  // namespace lvox
