// Turns a float grid as read from a file into SparseGrid's trees: values normalised in
// place (no copy), majorant trees from the value tree's leaves and tiles.
#include <openvdb/tree/LeafManager.h>
#include <tbb/combinable.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <type_traits>
#include <vector>

#include "src/core/error.h"
#include "volume/media/sparse_grid_trees.h"
#include "volume/media/vdb_loader.h"

namespace lvox {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using openvdb::FloatTree;
using LeafT = FloatTree::LeafNodeType;
constexpr int kLeafDim = static_cast<int>(LeafT::DIM);  // 8
constexpr int kLeafLog2 = static_cast<int>(LeafT::LOG2DIM);

struct Census {
  uint64_t negative = 0, nonFinite = 0;
  float mostNegative = 0.0f, max = 0.0f;
  void add(float v, uint64_t count) {
    if (!std::isfinite(v)) {
      nonFinite += count;
    } else if (v < 0.0f) {
      negative += count;
      mostNegative = std::min(mostNegative, v);
    } else {
      max = std::max(max, v);
    }
  }
  void merge(const Census& o) {
    negative += o.negative;
    nonFinite += o.nonFinite;
    mostNegative = std::min(mostNegative, o.mostNegative);
    max = std::max(max, o.max);
  }
};

float clean(float v) { return std::isfinite(v) && v > 0.0f ? v : 0.0f; }

// Inactive voxels and tiles and the background become 0 (only active values are density),
// negative values 0; returns what was found.
Census normalise(FloatTree& tree) {
  tbb::combinable<Census> partial;
  openvdb::tree::LeafManager<FloatTree> leaves(tree);
  leaves.foreach ([&partial](LeafT& leaf, size_t) {
    Census& c = partial.local();
    for (openvdb::Index i = 0; i < LeafT::SIZE; ++i) {
      if (!leaf.isValueOn(i)) {
        leaf.setValueOnly(i, 0.0f);
        continue;
      }
      const float v = leaf.getValue(i);
      c.add(v, 1);
      if (!(v >= 0.0f)) leaf.setValueOnly(i, 0.0f);
    }
  });
  Census census;
  partial.combine_each([&census](const Census& c) { census.merge(c); });
  auto tile = tree.beginValueAll();
  tile.setMaxDepth(FloatTree::ValueAllIter::LEAF_DEPTH - 1);  // tiles only
  for (; tile; ++tile) {
    const bool on = tile.isValueOn();
    if (on) census.add(*tile, tile.getBoundingBox().volume());
    if (!on || !(*tile >= 0.0f)) {
      tile.setValue(0.0f);
      if (!on) tile.setValueOff();
    }
  }
  tree.root().setBackground(0.0f, /*updateChildNodes=*/false);
  return census;
}

CoordBBox shiftDown(const CoordBBox& b, int log2) {
  return {Coord(b.min().x() >> log2, b.min().y() >> log2, b.min().z() >> log2),
          Coord(b.max().x() >> log2, b.max().y() >> log2, b.max().z() >> log2)};
}

// The maximum of each cell's children: cell c of the result covers the 8^3 cells 8c ..
// 8c + 7 of `fine` (leaves collapse to one cell, tiles to their box shifted down).
template <class FineTree>
MajorantTree::Ptr coarsen(const FineTree& fine) {
  static_assert(std::is_same_v<typename FineTree::LeafNodeType, LeafT>);
  openvdb::tree::LeafManager<const FineTree> leaves(fine);
  std::vector<float> leafMax(leaves.leafCount(), 0.0f);
  leaves.foreach ([&leafMax](const LeafT& leaf, size_t n) {
    float m = 0.0f;
    for (auto v = leaf.cbeginValueOn(); v; ++v) m = std::max(m, *v);
    leafMax[n] = m;
  });
  auto coarse = std::make_shared<MajorantTree>(0.0f);
  openvdb::tree::ValueAccessor<MajorantTree> acc(*coarse);
  for (size_t n = 0; n < leaves.leafCount(); ++n)
    if (leafMax[n] > 0.0f) {
      const Coord o = leaves.leaf(n).origin();
      const Coord c(o.x() >> kLeafLog2, o.y() >> kLeafLog2, o.z() >> kLeafLog2);
      acc.setValueOn(c, std::max(acc.getValue(c), leafMax[n]));
    }
  auto tile = fine.cbeginValueOn();
  tile.setMaxDepth(FineTree::ValueOnCIter::LEAF_DEPTH - 1);
  for (; tile; ++tile)
    if (*tile > 0.0f) coarse->fill(shiftDown(tile.getBoundingBox(), kLeafLog2), *tile, true);
  return coarse;
}

// Each cell's maximum over itself and its 26 neighbours (at least). Tiles are filled as
// boxes in increasing order of value, so the larger wins where they overlap, then voxels
// take the maximum cell by cell. A tile (whole nodes of 16^3 or more cells) is dilated by a
// leaf of 8 cells, not 1: the box stays leaf-aligned and fills as tiles, where a one-cell
// rim around a tile of 512^3 cells would allocate 25 k leaves.
MajorantTree::Ptr dilateMax(const MajorantTree& own) {
  auto dilated = std::make_shared<MajorantTree>(0.0f);
  std::vector<std::pair<float, CoordBBox>> tiles;
  auto tile = own.cbeginValueOn();
  tile.setMaxDepth(MajorantTree::ValueOnCIter::LEAF_DEPTH - 1);
  for (; tile; ++tile) {
    CoordBBox b = tile.getBoundingBox();
    b.expand(kLeafDim);
    tiles.emplace_back(*tile, b);
  }
  std::sort(tiles.begin(), tiles.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [value, box] : tiles) dilated->fill(box, value, true);
  openvdb::tree::ValueAccessor<MajorantTree> acc(*dilated);
  for (auto leaf = own.cbeginLeaf(); leaf; ++leaf)
    for (auto v = leaf->cbeginValueOn(); v; ++v) {
      if (!(*v > 0.0f)) continue;
      const Coord c = v.getCoord();
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const Coord n = c.offsetBy(dx, dy, dz);
            const float current = acc.getValue(n);
            if (current < *v || !acc.isValueOn(n)) acc.setValueOn(n, std::max(current, *v));
          }
    }
  return dilated;
}

}  // namespace

LowerNodeIndex::LowerNodeIndex(const openvdb::FloatTree& tree) {
  std::vector<const LowerT*> lowers;
  const auto& root = tree.root();
  for (auto tile = root.cbeginValueOn(); tile; ++tile) valuesOutside_ |= *tile > 0.0f;
  for (auto upper = root.cbeginChildOn(); upper; ++upper) {
    for (auto tile = upper->cbeginValueOn(); tile; ++tile) valuesOutside_ |= *tile > 0.0f;
    for (auto lower = upper->cbeginChildOn(); lower; ++lower) {
      const openvdb::Coord& o = lower->origin();
      if (inReach(o.x()) && inReach(o.y()) && inReach(o.z()))
        lowers.push_back(&*lower);
      else
        valuesOutside_ = true;
    }
  }
  // At most half full: a miss (empty space) ends after a probe or two.
  const size_t slots = std::bit_ceil(std::max<size_t>(2 * lowers.size(), 16));
  keys_.assign(slots, kEmpty);
  nodes_.assign(slots, nullptr);
  mask_ = slots - 1;
  for (const LowerT* lower : lowers) {
    const openvdb::Coord& o = lower->origin();
    const uint64_t key = keyOf(o.x(), o.y(), o.z());
    uint64_t h = hash(key);
    while (keys_[h] != kEmpty) h = (h + 1) & mask_;
    keys_[h] = key;
    nodes_[h] = lower;
  }
}

std::optional<LeafTable> LeafTable::build(const openvdb::FloatTree& tree,
                                          const openvdb::CoordBBox& activeBox,
                                          const LowerNodeIndex& index, size_t maxBytes) {
  if (activeBox.empty()) return std::nullopt;
  LeafTable t;
  size_t entries = 1;
  for (int a = 0; a < 3; ++a) {
    t.lo_[a] = activeBox.min()[a] >> kLog2;
    t.n_[a] = static_cast<uint32_t>((activeBox.max()[a] >> kLog2) - t.lo_[a] + 1);
    entries *= t.n_[a];
  }
  if (entries * sizeof(const float*) > maxBytes) return std::nullopt;
  // Regions no lower node holds are the background or an upper node's or the root's tile:
  // all 0 unless the index says otherwise.
  static const float kZeros[1 << (3 * kLog2)] = {};
  t.entries_.assign(entries, index.valuesOutside() ? nullptr : kZeros);
  for (auto upper = tree.root().cbeginChildOn(); upper; ++upper)
    for (auto lower = upper->cbeginChildOn(); lower; ++lower) {
      const LowerT& node = *lower;
      for (openvdb::Index n = 0; n < LowerT::NUM_VALUES; ++n) {
        const openvdb::Coord o = node.offsetToGlobalCoord(n);
        const auto x = static_cast<uint32_t>((o.x() >> kLog2) - t.lo_[0]);
        const auto y = static_cast<uint32_t>((o.y() >> kLog2) - t.lo_[1]);
        const auto z = static_cast<uint32_t>((o.z() >> kLog2) - t.lo_[2]);
        if (x >= t.n_[0] || y >= t.n_[1] || z >= t.n_[2]) continue;
        const float*& entry = t.entries_[(static_cast<size_t>(z) * t.n_[1] + y) * t.n_[0] + x];
        if (node.isChildMaskOn(n))
          entry = node.getTable()[n].getChild()->buffer().data();
        else
          entry = node.getTable()[n].getValue() == 0.0f ? kZeros : nullptr;
      }
    }
  return t;
}

std::shared_ptr<const SparseGrid::Trees> buildSparseTrees(openvdb::FloatGrid::Ptr grid,
                                                          const std::string& file,
                                                          const std::string& field,
                                                          GridLoadReport& report) {
  static std::atomic<uint64_t> nextId{1};
  FloatTree& tree = grid->tree();
  const Census census = normalise(tree);
  if (census.nonFinite > 0)
    throw InputError(file, field,
                     std::to_string(census.nonFinite) + " active voxels are NaN or infinite");
  report.clampedNegative = census.negative;
  report.mostNegative = census.mostNegative;
  report.activeVoxels = tree.activeVoxelCount();
  report.treeBytes = tree.memUsage();

  auto trees = std::make_shared<SparseGrid::Trees>();
  trees->values = grid;
  trees->activeVoxels = report.activeVoxels;
  trees->maxValue = clean(census.max);
  tree.evalActiveVoxelBoundingBox(trees->activeBox);
  // Lookups index voxels below 1e9 (SparseGrid::sampleIndex), in floats (exact to the voxel
  // below 2^24), and bounds add the stencils' reach in int: a grid reaching -2^31 (found by
  // fuzzing) overflowed them. Real grids lie far inside +-2^29.
  constexpr int kReach = 1 << 29;
  const openvdb::CoordBBox& box = trees->activeBox;
  for (int a = 0; a < 3; ++a)
    if (box.min()[a] < -kReach || box.max()[a] > kReach)
      throw InputError(file, field,
                       "active voxels at index " +
                           std::to_string(box.min()[a] < -kReach ? box.min()[a] : box.max()[a]) +
                           " (axis " + std::to_string(a) + "), beyond the +-2^29 lvox indexes");
  MajorantTree::Ptr blockMax = dilateMax(*coarsen(tree));
  MajorantTree::Ptr nodeMax = coarsen(*blockMax);
  blockMax->evalActiveVoxelBoundingBox(trees->blockCells);
  nodeMax->evalActiveVoxelBoundingBox(trees->nodeCells);
  trees->blockMax = blockMax;
  trees->nodeMax = nodeMax;
  trees->id = nextId.fetch_add(1);
  trees->lowerNodes.emplace(tree);
  trees->leafTable =
      LeafTable::build(tree, trees->activeBox, *trees->lowerNodes, report.treeBytes / 8);
  static_assert(kLeafDim == 8, "majorant blocks are the value tree's 8^3 leaves");
  return trees;
}

}  // namespace lvox
