#pragma once
// OpenVDB's side of SparseGrid, shared by volume/media's .cpp files only (OpenVDB is a
// private dependency of lvox_volume).
#include <openvdb/openvdb.h>

#include <cstdint>
#include <memory>
#include <string>

#include "volume/media/sparse_grid.h"

namespace lvox {

// The majorant trees' type: smaller internal nodes than the value tree's (8^3 children
// instead of 16^3 and 32^3), because they hold 1/512 of its cells and OpenVDB's standard
// upper nodes alone (32^3 entries) would weigh more than a small cloud's whole tree.
using MajorantTree = openvdb::tree::Tree4<float, 3, 3, 3>::Type;

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
  uint64_t id = 0;  // unique per process: keys the per-thread accessor slots
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
