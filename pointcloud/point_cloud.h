#pragma once
// The point cloud of the two-phase renderer: surfels and lvoxels in ONE octree (Gibson
// 2011). Construction sorts the elements along a Morton curve and reorders both sets in
// that order, so element indices change: use the cloud's own sets after construction.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "pointcloud/lvoxel_lattice.h"
#include "pointcloud/lvoxels.h"
#include "pointcloud/octree_node.h"
#include "pointcloud/surfel_cluster.h"
#include "pointcloud/surfels.h"
#include "src/core/spherical_harmonics.h"

namespace lvox {

// Deepest possible leaf (21 Morton bits per axis), whatever OctreeSettings::maxDepth says.
inline constexpr uint32_t kMaxOctreeDepth = 21;

struct OctreeSettings {
  uint32_t leafSize = 16;  // a node with more elements is split ...
  uint32_t maxDepth = 20;  // ... unless it is this deep (coincident points)
  // Keep the surfel cluster proxies (and the node cells they are clipped to). Gathers that
  // test every surfel exactly (cluster_solid_angle 0, the default) never read them: without
  // them a node costs 128 bytes less.
  bool surfelClusters = true;
};

struct PointCloudMemory {
  size_t surfelBytes = 0, lvoxelBytes = 0, octreeBytes = 0;
  size_t total() const { return surfelBytes + lvoxelBytes + octreeBytes; }
};

class PointCloud {
 public:
  PointCloud() = default;
  // Builds the octree in parallel (deterministic) and the cluster aggregates.
  PointCloud(SurfelSet surfels, LvoxelSet lvoxels, const OctreeSettings& settings = {});

  const CloudSurfels& surfels() const { return surfels_; }
  const LvoxelSet& lvoxels() const { return lvoxels_; }
  // Mutable access is for the light caches only (positions must not move); call
  // updateAggregates() after changing radiance or in-scatter.
  CloudSurfels& mutableSurfels() { return surfels_; }
  LvoxelSet& mutableLvoxels() { return lvoxels_; }

  const std::vector<OctreeNode>& nodes() const { return nodes_; }
  const std::vector<SurfelCluster>& surfelClusters() const { return surfelClusters_; }
  // The lvoxel clusters of the nodes that hold lvoxels, in node order (most nodes hold
  // surfels only); lvoxelClusterOf(node) is a node's index in it, or kNoLvoxelCluster.
  const std::vector<LvoxelCluster>& lvoxelClusters() const { return lvoxelClusters_; }
  static constexpr uint32_t kNoLvoxelCluster = ~0u;
  uint32_t lvoxelClusterOf(uint32_t node) const { return lvoxelClusterOf_[node]; }
  // Lvoxel cluster c's source coefficients (lvoxels().light.coefficients() of them; with
  // one, its sourceRadiance).
  const RGB* lvoxelClusterCoefficients(uint32_t c) const {
    return lvoxelClusterCoefficients_.empty() ? &lvoxelClusters_[c].sourceRadiance
                                              : &lvoxelClusterCoefficients_[c * kShCoefficients];
  }
  bool hasSurfelClusters() const { return keepSurfelClusters_; }
  bool empty() const { return nodes_.empty(); }

  // The traversal's layout (traversal.h), built with the octree from the elements'
  // geometry, which must not change afterwards: per inner node its children's bounds as
  // SIMD-ready arrays (8 lanes for the heap, up to 16 descendants for the nearest-disk
  // search), per node its block, and the disks (the surfels' own records) and cubes
  // packed in octree order.
  const std::vector<OctreeChildren>& childBlocks() const { return childBlocks_; }
  const std::vector<WideChildren>& wideBlocks() const { return wideBlocks_; }
  const std::vector<TraversalNode>& traversalNodes() const { return traversalNodes_; }
  const std::vector<DiskElement>& disks() const { return surfels_.disks(); }
  // A surfel's border cut (one that removes nothing where it has none): only the disks that
  // are cut keep one.
  const DiskClip& diskClip(uint32_t surfel) const {
    static const DiskClip kNone{};
    const uint32_t flags = surfels_.disks()[surfel].flags;
    return (flags & DiskElement::kClipped) ? clips_[flags >> DiskElement::kClipShift] : kNone;
  }
  const std::vector<CubeElement>& cubes() const { return cubes_; }
  // The cubes as one lattice's cells, for lvoxel-only rays (null when they are not on one).
  const LvoxelLattice* lvoxelLattice() const { return lattice_ ? &*lattice_ : nullptr; }
  // How far from a ray's origin no lvoxel cluster can be used when clusters are used below
  // `maxSolidAngle` (TraversalOptions): within it the traversal visits every lvoxel.
  float lvoxelClusterFreeReach(float maxSolidAngle) const;
  // The root as the nearest-disk search starts from it (a WideChildren reference).
  uint32_t searchRoot(uint32_t& surfelEnd) const;
  // True while the layout's child bounds equal the nodes' (tests: updates keep them).
  bool traversalLayoutMatchesNodes() const;
  // Depth of the deepest leaf (root = 0).
  uint32_t depth() const { return empty() ? 0 : static_cast<uint32_t>(levelBegin_.size()) - 2; }

  // Recomputes the cluster aggregates bottom-up (parallel per level).
  void updateAggregates();

  PointCloudMemory memory() const;
  size_t memoryBytes() const { return memory().total(); }
  // The traversal layout's share of memory().octreeBytes.
  size_t traversalBytes() const;
  // Nodes, their cells and their cluster aggregates, per node (lvoxel clusters apart:
  // only nodes that hold lvoxels have one).
  size_t bytesPerNode() const {
    return sizeof(OctreeNode) + sizeof(uint32_t) +
           (keepSurfelClusters_ ? sizeof(Bounds3) + sizeof(SurfelCluster) : 0);
  }

 private:
  void build(SurfelSet surfels, const OctreeSettings& settings);
  void computeBounds();
  void buildTraversalLayout();
  void assignLvoxelClusters();

  CloudSurfels surfels_;
  LvoxelSet lvoxels_;
  bool keepSurfelClusters_ = true;
  std::vector<OctreeNode> nodes_;
  std::vector<Bounds3> cells_;        // each node's exact octree cell (cells of a level tile space)
  std::vector<uint32_t> levelBegin_;  // nodes of depth d are [levelBegin_[d], levelBegin_[d+1])
  std::vector<SurfelCluster> surfelClusters_;
  std::vector<uint32_t> lvoxelClusterOf_;  // per node
  uint32_t lvoxelClusterCount_ = 0;
  std::vector<LvoxelCluster> lvoxelClusters_;
  std::vector<RGB> lvoxelClusterCoefficients_;  // kShCoefficients per cluster, directional only
  std::vector<OctreeChildren> childBlocks_;
  std::vector<WideChildren> wideBlocks_;
  std::vector<TraversalNode> traversalNodes_;
  std::vector<DiskClip> clips_;  // the cuts of the disks that have one
  std::vector<CubeElement> cubes_;
  std::optional<LvoxelLattice> lattice_;
  float minLvoxelClusterRadius_ = kInf;  // of the nodes that hold lvoxels and may cluster
};

}  // namespace lvox
