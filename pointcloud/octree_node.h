#pragma once
// Nodes and cluster aggregates of the point cloud's octree. Nodes live in one flat array,
// children of a node are contiguous, and every subtree owns a contiguous range of surfels
// and of lvoxels (the cloud stores its elements in octree order).
#include <cstdint>

#include "src/core/math.h"

namespace lvox {

struct OctreeNode {
  Bounds3 bounds;  // loose: every element's full extent (disk or cube) and the cluster proxies
  uint32_t childBegin = 0;
  uint32_t surfelBegin = 0, surfelEnd = 0;
  uint32_t lvoxelBegin = 0, lvoxelEnd = 0;
  uint8_t childCount = 0;  // 0: leaf
  bool isLeaf() const { return childCount == 0; }
  uint32_t elementCount() const { return surfelEnd - surfelBegin + lvoxelEnd - lvoxelBegin; }
};

// The traversal's view of an inner node's children (traversal.h): their loose bounds as
// a structure of arrays, so that one SIMD slab test covers four children, and what each
// child holds, so that a leaf's disks are found without loading the leaf. W = 8 lanes
// (256 bytes) hold one octree node's children, for the heap traversal; W = 16 (512 bytes)
// hold up to 16 of its descendants, for the nearest-disk search, which then goes two
// octree levels per block where surfaces split in four.
template <int W>
struct alignas(64) ChildBlock {
  static constexpr int kWidth = W;
  static constexpr uint32_t kLeaf = 1u << 31;     // the child is a leaf ...
  static constexpr uint32_t kSurfels = 1u << 30;  // ... it holds surfels ...
  static constexpr uint32_t kLvoxels = 1u << 29;  // ... and/or lvoxels
  static constexpr uint32_t kIndexMask = kLvoxels - 1;
  float lo[3][W];  // [axis][child]
  float hi[3][W];
  // Flags | index: a leaf's first surfel, an inner node's block index; 0 for an unused
  // lane (every child holds something, so a used lane has a flag set).
  uint32_t ref[W];
  uint32_t surfelEnd[W];  // leaves: one past the last surfel
};
using OctreeChildren = ChildBlock<8>;
using WideChildren = ChildBlock<16>;

// A node as the heap traversal opens it, 16 bytes instead of OctreeNode's 48.
struct TraversalNode {
  uint32_t ref = 0;        // OctreeChildren::ref encoding: flags | first surfel or block index
  uint32_t surfelEnd = 0;  // leaves
  uint32_t first = 0;      // inner nodes: first child's node index; leaves: first lvoxel
  uint32_t lvoxelEnd = 0;  // leaves
};

// A node's lvoxels seen from far away: one homogeneous box, the bounds of their cubes,
// with the same total extinction cross-section sum(sigma_t V) (so its optical depth
// integrated over its projected area is exact: the integral of the chord over any
// projection of a convex body is its volume) and the cross-section-weighted mean source
// radiance. A full cell's cluster is the cell itself; a thin layer's is the layer. The box
// lies inside the node's bounds, which every ray into the cluster crosses. (Until stop 26
// it was a cube of the lvoxels' volume at their centroid, which reached past the lvoxels
// of a partly filled node, outside its bounds: rays through a thin layer along its plane
// saw 32 % of its cross-section, docs/results.md.)
struct LvoxelCluster {
  Bounds3 box;
  RGB sigmaT{0, 0, 0};  // cross-section / box volume
  RGB sourceRadiance{0, 0, 0};
  bool empty() const { return !(box.lo.x < box.hi.x); }
};

}  // namespace lvox
