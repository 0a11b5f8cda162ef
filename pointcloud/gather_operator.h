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
#include <functional>
#include <vector>

#include "pointcloud/gather.h"
#include "src/core/check.h"
#include "src/core/progress.h"

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
  // The same into `v`, reusing its storage (passes refill one vector).
  void valuesInto(const PointCloud& cloud, const RGB& backgroundRadiance,
                  std::vector<RGB>& v) const;

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
  // every part's result is the whole operator's, exactly. `reserve(bytes)`, when given, is
  // told each block's bytes as it is stored (from worker threads) and may throw to stop the
  // build: a memory budget (src/core/memory_budget.h).
  template <class RecordRow>
  GatherOperator(const PointCloud& cloud, size_t rows, RecordRow&& record, int part = 0,
                 int parts = 1, const std::function<void(uint64_t)>& reserve = {});

  size_t rows() const { return rows_; }
  size_t entries() const;
  size_t memoryBytes() const;
  // out[r] = sum of weight * values[column] over row r.
  void apply(const std::vector<RGB>& values, std::vector<RGB>& out) const;
  // sink(r, that sum) for every row r, without a vector of all rows (it is as large as the
  // cloud): blocks of kRowsPerBlock rows in parallel, a block's rows in order on one thread.
  // Rows of blocks another part owns get 0.
  template <class Sink>
  void forEachRow(const std::vector<RGB>& values, Sink&& sink) const;
  static constexpr size_t kRowsPerBlock = 512;
  size_t blockCount() const { return blocks_.size(); }
  const GatherColumns& columns() const { return columns_; }

 private:
  // A block's weights are stored grey (one float) when all of them are: media with a
  // colourless extinction (and no media at all) give grey weights, and a float per entry
  // halves the operator, its largest memory item (issue 13: bytes per element).
  struct Block {
    std::vector<uint32_t> rowEnd;  // entries of row k of the block end at rowEnd[k]
    std::vector<uint32_t> column;
    std::vector<float> greyWeight;  // either this ...
    std::vector<RGB> colourWeight;  // ... or this holds the weights
  };
  static void appendMerged(std::vector<GatherEntry>& row, std::vector<GatherEntry>& entries,
                           std::vector<uint32_t>& rowEnd);
  static void store(const std::vector<GatherEntry>& entries, Block& block);
  template <class Weight, class Sink>
  static void applyBlock(const Block& block, const Weight& weight, size_t firstRow,
                         const std::vector<RGB>& values, Sink& sink);
  bool owns(size_t block) const { return block % parts_ == part_; }

  GatherColumns columns_{PointCloud()};
  size_t rows_ = 0;
  std::vector<Block> blocks_;
  size_t part_ = 0, parts_ = 1;
};

template <class RecordRow>
GatherOperator::GatherOperator(const PointCloud& cloud, size_t rows, RecordRow&& record, int part,
                               int parts, const std::function<void(uint64_t)>& reserve)
    : columns_(cloud),
      rows_(rows),
      blocks_((rows + kRowsPerBlock - 1) / kRowsPerBlock),
      part_(static_cast<size_t>(part)),
      parts_(static_cast<size_t>(std::max(parts, 1))) {
  LVOX_CHECK(part >= 0 && part_ < parts_, "gather operator part out of range");
  uint64_t ownedRows = 0;
  for (size_t b = 0; b < blocks_.size(); ++b)
    if (owns(b)) ownedRows += std::min(rows, (b + 1) * kRowsPerBlock) - b * kRowsPerBlock;
  Progress::global().addWork(ownedRows);  // tracing the rows is most of the phase
  tbb::parallel_for(size_t(0), blocks_.size(), [&](size_t b) {
    if (!owns(b)) return;
    Block& block = blocks_[b];
    const size_t begin = b * kRowsPerBlock, end = std::min(rows, begin + kRowsPerBlock);
    block.rowEnd.reserve(end - begin);
    std::vector<GatherEntry> row, entries;
    TraversalScratch scratch;
    for (size_t r = begin; r < end; ++r) {
      row.clear();
      GatherRecorder recorder{columns_, row};
      record(r, recorder, scratch);
      appendMerged(row, entries, block.rowEnd);
    }
    store(entries, block);
    Progress::global().advance(end - begin);
    if (reserve)
      reserve(block.column.size() * sizeof(uint32_t) + block.greyWeight.size() * sizeof(float) +
              block.colourWeight.size() * sizeof(RGB) + block.rowEnd.size() * sizeof(uint32_t));
  });
}

template <class Weight, class Sink>
void GatherOperator::applyBlock(const Block& block, const Weight& weight, size_t firstRow,
                                const std::vector<RGB>& values, Sink& sink) {
  uint32_t begin = 0;
  for (size_t k = 0; k < block.rowEnd.size(); ++k) {
    RGB sum(0.0f);
    for (uint32_t e = begin; e < block.rowEnd[k]; ++e) sum += values[block.column[e]] * weight[e];
    sink(firstRow + k, sum);
    begin = block.rowEnd[k];
  }
}

template <class Sink>
void GatherOperator::forEachRow(const std::vector<RGB>& values, Sink&& sink) const {
  tbb::parallel_for(size_t(0), blocks_.size(), [&](size_t b) {
    if (!owns(b)) {  // another process's rows: zero here, so the parts sum to the whole
      for (size_t r = b * kRowsPerBlock; r < std::min(rows_, (b + 1) * kRowsPerBlock); ++r)
        sink(r, RGB(0.0f));
      return;
    }
    const Block& block = blocks_[b];
    if (block.colourWeight.empty())
      applyBlock(block, block.greyWeight, b * kRowsPerBlock, values, sink);
    else
      applyBlock(block, block.colourWeight, b * kRowsPerBlock, values, sink);
  });
}

}  // namespace lvox
