#pragma once
// The point cloud built in parallel across the ranks of a Collective and exchanged
// (docs/cluster.md), so that no rank repeats another's work and every rank ends with the
// cloud one process builds, bit for bit:
//  - surfels: rank r of N samples the triangles of its slice of the mesh (contiguous
//    ranges balanced by area, so in triangle order the slices are the whole set) and the
//    slices are allgathered and concatenated in rank order; then each rank probes an
//    equal range of the whole set for burial (each surfel's probes are numbered by its
//    index) and the marks, a byte per surfel, are allgathered too;
//  - lvoxels: rank r samples the slices of grid cells k (along z) with k mod N = r, and the
//    shares, exchanged, are merged in cell order (the one-process order);
//  - the lvoxels' direct light: cells in blocks, block b on rank b mod N, summed over the
//    ranks (the others add zeros, which is exact).
// The octree is then built by every rank from the same elements (deterministic). What
// crosses the ranks is plain arrays (src/core/byte_blocks.h), checked on receipt.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pointcloud/lvoxels.h"
#include "pointcloud/surfels.h"
#include "src/core/collective.h"
#include "src/world/world.h"

namespace lvox {

// Triangles [first[r], first[r + 1]) are rank r's: contiguous ranges of about equal area.
std::vector<size_t> triangleSlices(const TriangleMesh& mesh, int ranks);

// One rank's surfels as bytes (position, normal, radius, albedo, triangle, clip, enclosed
// sides; the radiance is not cached yet) and back. `from` names the sender in errors.
std::string surfelsToBytes(const SurfelSet& surfels);
void appendSurfelsFromBytes(const std::string& bytes, const std::string& from, SurfelSet& out);

// Every rank passes its slice (in rank order, the slices are the whole set) and receives
// the whole set. With one rank, the slice itself.
SurfelSet allgatherSurfels(SurfelSet slice, Collective& team);

// Per medium, every rank's share of its lvoxels (positions, sizes, coefficients and grid
// cells; no light yet) to every rank, merged in cell order into each medium's whole set,
// its cells occupied in that order. Every rank passes one set per medium, on one grid.
std::vector<LvoxelSet> allgatherLvoxels(const std::vector<LvoxelSet>& shares, Collective& team);

}  // namespace lvox
