#pragma once
// A scalar OpenVDB grid read in place, never copied into a dense array: the memory is the
// tree's own (its active leaves and tiles), whatever the grid's bounding box.
//
// Lookups find their leaf through an index of the tree's lower internal nodes (a hash of
// their positions, sparse_grid_trees.h), and each thread keeps the leaf it hit last, so
// consecutive lookups along a ray mostly cost a compare. Beside the values the grid keeps two
// majorant trees built from the value tree's own nodes: the largest value interpolation can return
// in each 8^3 block of voxels (a leaf of the tree) and in each 64^3 block (a leaf of the block
// tree). Ray walks over them are hierarchical DDAs that jump over empty nodes of the majorant tree,
// at any level.
//
// OpenVDB stays out of this header (it is a private dependency of lvox_volume): the trees
// live behind `Trees`, defined in sparse_grid_trees.h.
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "src/core/math.h"
#include "volume/media/interpolation.h"

namespace lvox {

// The granularity of the piecewise-constant majorant that tracking uses along a ray.
enum class MajorantLevel : uint8_t {
  kBlock,   // 8^3 voxels
  kNode,    // 64^3 voxels
  kGlobal,  // one majorant for the whole grid
};

struct MajorantSpan {
  float t0, t1;
  float majorant;  // >= the interpolated value anywhere on [t0, t1), in grid units
};

class SparseGrid {
 public:
  struct Trees;  // sparse_grid_trees.h

  SparseGrid() = default;
  // `indexToWorld` maps voxel indices (centres at integers, as in OpenVDB) to the scene.
  SparseGrid(std::shared_ptr<const Trees> trees, const Transform& indexToWorld);

  bool empty() const { return trees_ == nullptr; }
  // Value at a world position, or at an index-space position.
  float sample(const Vec3& world, Interpolation interp) const {
    return sampleIndex(worldToIndex_.point(world), interp);
  }
  float sampleIndex(const Vec3& index, Interpolation interp) const;
  float voxel(int i, int j, int k) const;
  float maxValue() const { return maxValue_; }
  uint64_t activeVoxels() const;

  const Transform& indexToWorld() const { return indexToWorld_; }
  const Transform& worldToIndex() const { return worldToIndex_; }
  // World-space bounds of the active voxels, padded by the 2-voxel reach of the widest
  // (tricubic) stencil.
  Bounds3 worldBounds() const { return worldBounds_; }
  // World-space boxes of the 8^3 blocks where interpolation can be non-zero.
  std::vector<Bounds3> occupiedWorldBoxes() const;

  // Majorant spans of `ray` (world space) over [tmin, tmax], in order; spans whose
  // majorant is 0 are left out, adjacent spans with the same majorant are merged.
  // `cells` (if given) counts the cells and empty nodes the walk visited.
  void majorantSpans(const Ray& ray, float tmin, float tmax, MajorantLevel level,
                     std::vector<MajorantSpan>& out, uint64_t* cells = nullptr) const;
  // Sorted, merged t-intervals of `ray` over [tmin, tmax] where the grid can be non-zero.
  void intervals(const Ray& ray, float tmin, float tmax,
                 std::vector<std::pair<float, float>>& out) const;

  // The level whose tracking costs least: expected cost per ray of walking the majorant
  // cells plus one lookup per tentative collision (optical depth of the majorant times
  // `densityScale`, at the cost of `interp`), averaged over fixed rays through the grid
  // (deterministic: the same grid always gets the same level).
  MajorantLevel cheapestMajorantLevel(float densityScale, Interpolation interp) const;

  // Bytes of the value tree and the majorant trees (OpenVDB's memUsage).
  size_t memoryBytes() const;
  // Whether lookups find leaves through a flat table over the active box (built where it
  // costs at most 1/8 of the tree's bytes; else through the lower-node index).
  bool hasLeafTable() const;

 private:
  std::shared_ptr<const Trees> trees_;
  Transform indexToWorld_, worldToIndex_;
  Bounds3 worldBounds_;
  float maxValue_ = 0.0f;
};

}  // namespace lvox
