#pragma once
// The interreflection's gathers as one sparse linear map. What a gather returns is linear
// in the cloud's cached radiance: every element its rays reach contributes its radiance
// times a weight (the transmittance in front, the lvoxel's opacity, the ray's quadrature
// weight) that depends on geometry and media only (GatherRayWeights). Tracing the rays
// once and keeping the weights turns each further interreflection pass into a sparse
// matrix-vector product: passes no longer traverse the octree, so converging the bounce
// series costs little more than its first pass.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pointcloud/gather.h"
#include "src/core/check.h"

namespace lvox {

// Columns: every radiance a gather ray can pick up, in one flat vector.
struct GatherColumns {
  size_t surfels = 0, lvoxels = 0, surfelClusters = 0, lvoxelClusters = 0;

  explicit GatherColumns(const PointCloud& cloud);
  uint32_t surfel(uint32_t i, bool front) const { return front ? i : index(surfels + i); }
  uint32_t lvoxel(uint32_t i) const { return index(2 * surfels + i); }
  uint32_t surfelCluster(uint32_t n, bool front) const {
    return index(2 * surfels + lvoxels + (front ? 0 : surfelClusters) + n);
  }
  uint32_t lvoxelCluster(uint32_t n) const {
    return index(2 * surfels + lvoxels + 2 * surfelClusters + n);
  }
  uint32_t background() const { return index(size() - 1); }
  size_t size() const { return 2 * surfels + lvoxels + 2 * surfelClusters + lvoxelClusters + 1; }
  // The cloud's radiance as it stands (call updateAggregates first), in column order.
  std::vector<RGB> values(const PointCloud& cloud, const RGB& backgroundRadiance) const;

 private:
  static uint32_t index(size_t i) { return static_cast<uint32_t>(i); }
};

struct GatherEntry {
  uint32_t column;
  RGB weight;
};

// Appends a gather's weights to one row (GatherRayWeights' sink).
struct GatherRecorder {
  const GatherColumns& columns;
  std::vector<GatherEntry>& entries;

  void surfel(uint32_t i, bool front, const RGB& w) { add(columns.surfel(i, front), w); }
  void surfelCluster(uint32_t n, bool front, const RGB& w) {
    add(columns.surfelCluster(n, front), w);
  }
  void lvoxel(uint32_t i, const RGB& w) { add(columns.lvoxel(i), w); }
  void lvoxelCluster(uint32_t n, const RGB& w) { add(columns.lvoxelCluster(n), w); }
  void addBackground(const RGB& w) { add(columns.background(), w); }
  void add(uint32_t column, const RGB& w) {
    LVOX_DCHECK(column < columns.size(), "gather column out of range");
    if (maxComponent(w) > 0.0f) entries.push_back({column, w});
  }
};

class GatherOperator {
 public:
  GatherOperator() = default;
  // record(row, GatherRecorder&, TraversalScratch&) traces row `row`'s gather into the
  // recorder. Rows are built in parallel in fixed blocks: the operator does not depend on
  // the thread schedule. Split over `parts` processes, this one (`part`) traces only the
  // blocks b with b % parts == part, and apply() gives 0 in the others' rows: the sum of
  // every part's result is the whole operator's, exactly.
  template <class RecordRow>
  GatherOperator(const PointCloud& cloud, size_t rows, RecordRow&& record, int part = 0,
                 int parts = 1);

  size_t rows() const { return rows_; }
  size_t entries() const;
  size_t memoryBytes() const;
  // out[r] = sum of weight * values[column] over row r.
  void apply(const std::vector<RGB>& values, std::vector<RGB>& out) const;
  const GatherColumns& columns() const { return columns_; }

 private:
  static constexpr size_t kRowsPerBlock = 512;
  struct Block {
    std::vector<uint32_t> rowEnd;  // entries of row k of the block end at rowEnd[k]
    std::vector<GatherEntry> entries;
  };
  static void appendMerged(std::vector<GatherEntry>& row, Block& block);
  bool owns(size_t block) const { return block % parts_ == part_; }

  GatherColumns columns_{PointCloud()};
  size_t rows_ = 0;
  std::vector<Block> blocks_;
  size_t part_ = 0, parts_ = 1;
};

template <class RecordRow>
GatherOperator::GatherOperator(const PointCloud& cloud, size_t rows, RecordRow&& record, int part,
                               int parts)
    : columns_(cloud),
      rows_(rows),
      blocks_((rows + kRowsPerBlock - 1) / kRowsPerBlock),
      part_(static_cast<size_t>(part)),
      parts_(static_cast<size_t>(std::max(parts, 1))) {
  LVOX_CHECK(part >= 0 && part_ < parts_, "gather operator part out of range");
  tbb::parallel_for(size_t(0), blocks_.size(), [&](size_t b) {
    if (!owns(b)) return;
    Block& block = blocks_[b];
    const size_t begin = b * kRowsPerBlock, end = std::min(rows, begin + kRowsPerBlock);
    block.rowEnd.reserve(end - begin);
    std::vector<GatherEntry> row;
    TraversalScratch scratch;
    for (size_t r = begin; r < end; ++r) {
      row.clear();
      GatherRecorder recorder{columns_, row};
      record(r, recorder, scratch);
      appendMerged(row, block);
    }
    block.entries.shrink_to_fit();
  });
}

}  // namespace lvox
