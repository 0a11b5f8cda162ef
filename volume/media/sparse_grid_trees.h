#pragma once
// OpenVDB's side of SparseGrid, shared by volume/media's .cpp files only (OpenVDB is a
// private dependency of lvox_volume).
#include <openvdb/openvdb.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "volume/media/sparse_grid.h"

namespace lvox {

// The majorant trees' type: smaller internal nodes than the value tree's (8^3 children
// instead of 16^3 and 32^3), because they hold 1/512 of its cells and OpenVDB's standard
// upper nodes alone (32^3 entries) would weigh more than a small cloud's whole tree.
using MajorantTree = openvdb::tree::Tree4<float, 3, 3, 3>::Type;

// The value tree's lower internal nodes (16^3 leaves, 128^3 voxels) by position, in an
// open-addressing hash table: a lookup that leaves the leaf it used last finds its leaf with
// one hash probe and the node's own mask and table, where a value accessor that missed its
// caches descended OpenVDB's root map and upper nodes (60-80 ns a random lookup, 3-6x the
// dense array). It holds pointers only: 16 bytes per lower node beside OpenVDB's 33 kB.
class LowerNodeIndex {
 public:
  using LowerT = openvdb::FloatTree::RootNodeType::ChildNodeType::ChildNodeType;
  static constexpr int kLog2 = 7;  // voxels per side: 128
  // Lower nodes within +-2^27 voxels of the origin are indexed (21 bits per axis).
  static constexpr int kReach = 1 << 27;

  explicit LowerNodeIndex(const openvdb::FloatTree& tree);
  // The lower node holding voxel (i, j, k), or nullptr: none (or out of reach).
  const LowerT* find(int i, int j, int k) const {
    if (!inReach(i) || !inReach(j) || !inReach(k)) return nullptr;
    const uint64_t key = keyOf(i, j, k);
    for (uint64_t h = hash(key);; h = (h + 1) & mask_) {
      if (keys_[h] == key) return nodes_[h];
      if (keys_[h] == kEmpty) return nullptr;
    }
  }
  // False when every voxel outside the indexed lower nodes is 0 (no active upper or root
  // tile, nothing out of reach): a lookup that misses the index is then 0.
  bool valuesOutside() const { return valuesOutside_; }
  size_t memoryBytes() const { return keys_.size() * (sizeof(uint64_t) + sizeof(void*)); }

 private:
  static constexpr uint64_t kEmpty = ~uint64_t{0};  // keys use 63 bits
  static bool inReach(int c) { return c >= -kReach && c < kReach; }
  static uint64_t keyOf(int i, int j, int k) {
    const auto field = [](int c) { return static_cast<uint64_t>((c >> kLog2) & 0x1fffff); };
    return field(i) | field(j) << 21 | field(k) << 42;
  }
  uint64_t hash(uint64_t key) const { return (key * 0x9E3779B97F4A7C15ull >> 20) & mask_; }

  std::vector<uint64_t> keys_;
  std::vector<const LowerT*> nodes_;
  uint64_t mask_ = 0;
  bool valuesOutside_ = false;
};

// The value tree's leaf regions over its active box in a flat array: a lookup that leaves
// its leaf finds the next with one load, where the lower-node index takes a hash probe and
// the node's table (dependent loads: random lookups on the WDAS cloud took 1.8x the dense
// array's time). An entry is a leaf's buffer, a shared buffer of zeros for a region that is
// 0 throughout, or nullptr for the index to answer (a tile of another value). Built only
// when it costs at most 1/8 of the tree's bytes.
class LeafTable {
 public:
  using LowerT = LowerNodeIndex::LowerT;
  static constexpr int kLog2 = 3;  // voxels per leaf side: 8

  // nullopt when the table would cost more than `maxBytes`.
  static std::optional<LeafTable> build(const openvdb::FloatTree& tree,
                                        const openvdb::CoordBBox& activeBox,
                                        const LowerNodeIndex& index, size_t maxBytes);
  const float* find(int i, int j, int k) const {
    const auto x = static_cast<uint32_t>((i >> kLog2) - lo_[0]);
    const auto y = static_cast<uint32_t>((j >> kLog2) - lo_[1]);
    const auto z = static_cast<uint32_t>((k >> kLog2) - lo_[2]);
    if (x >= n_[0] || y >= n_[1] || z >= n_[2]) return nullptr;
    return entries_[(static_cast<size_t>(z) * n_[1] + y) * n_[0] + x];
  }
  size_t memoryBytes() const { return entries_.size() * sizeof(const float*); }

 private:
  int lo_[3] = {0, 0, 0};      // the first region, in leaves
  uint32_t n_[3] = {0, 0, 0};  // regions per axis
  std::vector<const float*> entries_;
};

struct SparseGrid::Trees {
  // The values: inactive voxels and tiles and the background are 0, negative values are
  // clamped to 0 (counted in GridLoadReport), non-finite values were refused.
  openvdb::FloatGrid::ConstPtr values;
  // Majorant trees: a cell of `blockMax` is an 8^3 block of voxels (cell c covers voxels
  // 8c .. 8c + 7, the tree's leaves) holding the largest value of the block and its 26
  // neighbours, so it bounds every stencil that reaches into the block. A cell of `nodeMax`
  // is 64^3 voxels (a leaf of `blockMax`): the largest `blockMax` in it.
  MajorantTree::ConstPtr blockMax, nodeMax;
  openvdb::CoordBBox blockCells, nodeCells;  // their active cells
  openvdb::CoordBBox activeBox;              // of the values' active voxels
  uint64_t activeVoxels = 0;
  float maxValue = 0.0f;
  uint64_t id = 0;                           // unique per process: keys the per-thread leaf caches
  std::optional<LowerNodeIndex> lowerNodes;  // of `values`, once normalised
  std::optional<LeafTable> leafTable;        // over `activeBox`, where it is cheap
};

struct GridLoadReport;

// Normalises `grid` in place (see Trees::values) and builds the majorant trees (tiles stay
// tiles there too, so a small file declaring a tile of 4096^3 voxels costs little). Throws
// InputError(file, field, ...) for non-finite active values.
std::shared_ptr<const SparseGrid::Trees> buildSparseTrees(openvdb::FloatGrid::Ptr grid,
                                                          const std::string& file,
                                                          const std::string& field,
                                                          GridLoadReport& report);

}  // namespace lvox
