#pragma once
// The interreflection's gathers as one sparse linear map. What a gather returns is linear
// in the cloud's cached radiance: every element its rays reach contributes its radiance
// times a weight (the transmittance in front, the lvoxel's opacity, the ray's quadrature
// weight) that depends on geometry and media only (GatherRayWeights). Tracing the rays
// once and keeping the weights turns each further interreflection pass into a sparse
// matrix-vector product: passes no longer traverse the octree, so converging the bounce
// series costs little more than its first pass.
#include <Imath/half.h>
#include <tbb/parallel_for.h>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "pointcloud/gather.h"
#include "src/core/check.h"
#include "src/core/progress.h"
#include "src/core/spherical_harmonics.h"

namespace lvox {

// A directional column's coefficient as a pass reads it: red, green, blue and a zero, one
// SIMD register. A ray's radiance from an lvoxel is then `coefficients` multiply-adds of
// whole registers (GatherOperator::applyBlock, the passes' hot loop in anisotropic media).
struct alignas(16) PaddedRGB {
  float c[4] = {0.0f, 0.0f, 0.0f, 0.0f};
};

// Columns: every radiance a gather ray can pick up, in one flat vector. A surfel cluster
// has one column per power coefficient (surfel_cluster.h): its radiance along a ray is
// linear in them, with weights of the ray's direction. Lvoxels and their clusters come
// last: in anisotropic media their radiance depends on the ray's direction (the columns
// from firstDirectional() on, which then also have coefficients).
struct GatherColumns {
  size_t surfels = 0, lvoxels = 0, surfelClusters = 0, lvoxelClusters = 0;
  int coefficients = 1;  // of the lvoxels' light: 1, or 9 where their radiance has direction

  explicit GatherColumns(const PointCloud& cloud);
  uint32_t surfel(uint32_t i, bool front) const { return front ? i : index(surfels + i); }
  uint32_t surfelCluster(uint32_t n, int coefficient) const {
    return index(2 * surfels + static_cast<size_t>(n) * kShCoefficients +
                 static_cast<size_t>(coefficient));
  }
  uint32_t background() const { return index(2 * surfels + kShCoefficients * surfelClusters); }
  uint32_t firstDirectional() const { return background() + 1; }
  uint32_t lvoxel(uint32_t i) const { return index(firstDirectional() + i); }
  uint32_t lvoxelCluster(uint32_t n) const { return index(firstDirectional() + lvoxels + n); }
  size_t size() const {
    return 2 * surfels + lvoxels + kShCoefficients * surfelClusters + lvoxelClusters + 1;
  }
  bool directional() const { return coefficients > 1; }
  // The cloud's radiance as it stands (call updateAggregates first), in column order; for
  // lvoxels and their clusters, the mean over directions.
  std::vector<RGB> values(const PointCloud& cloud, const RGB& backgroundRadiance) const;
  // The same into `v`, reusing its storage (passes refill one vector); with directional
  // lvoxels also their source coefficients into `directional` (coefficients per column
  // from firstDirectional() on).
  void valuesInto(const PointCloud& cloud, const RGB& backgroundRadiance, std::vector<RGB>& v,
                  std::vector<PaddedRGB>* directional = nullptr) const;

 private:
  static uint32_t index(size_t i) { return static_cast<uint32_t>(i); }
};

struct GatherEntry {
  uint32_t column;
  uint32_t ray;  // the ray of its row (directional operators only; 0 otherwise)
  RGB weight;
};

// Appends a gather's weights to one row (GatherRayWeights' sink). With directional
// columns it also keeps each ray's direction, and the entries say which ray they are of.
struct GatherRecorder {
  const PointCloud& cloud;
  const GatherColumns& columns;
  std::vector<GatherEntry>& entries;
  std::vector<Vec3>* rays = nullptr;  // directional operators: the row's ray directions
  Vec3 direction{0, 0, 1};
  // The light the row's hits reflect from the delta lights (GatherOptions::hitLight) does
  // not change from pass to pass: it is no column but the row's constant, projected as the
  // operator projects its rays (columns.coefficients values). The caller owns it; null
  // when the gathers have neither a hit light nor a background of their row's own.
  RGB* constant = nullptr;
  // With `constant`: the radiance the row's escaping rays see. It is constant too, so it
  // joins `constant` and not the background column. Null: the column.
  const RGB* background = nullptr;

  void beginRay(const Vec3& dir) {
    direction = dir;
    if (rays) rays->push_back(dir);
  }
  void surfel(uint32_t i, bool front, const RGB& w) { add(columns.surfel(i, front), w); }
  void surfelCluster(uint32_t n, const RGB& w) {
    float g[kShCoefficients];
    if (!cloud.surfelClusters()[n].radianceWeights(direction, g)) return;
    for (int k = 0; k < kShCoefficients; ++k) add(columns.surfelCluster(n, k), w * g[k]);
  }
  void lvoxel(uint32_t i, const RGB& w) { add(columns.lvoxel(i), w); }
  void lvoxelCluster(uint32_t n, const RGB& w) { add(columns.lvoxelCluster(n), w); }
  void addBackground(const RGB& w) {
    if (background)
      addConstant(w * *background);
    else
      add(columns.background(), w);
  }
  void surfaceLight(const RGB& weighted) { addConstant(weighted); }
  void addConstant(const RGB& weighted) {
    LVOX_CHECK(constant, "a gather with a constant records into a row without one");
    if (!columns.directional()) {
      constant[0] += weighted;
      return;
    }
    float yhat[kShCoefficients];
    shBasis(direction, columns.coefficients, yhat);
    for (int k = 0; k < columns.coefficients; ++k) constant[k] += weighted * yhat[k];
  }
  void add(uint32_t column, const RGB& w) {
    LVOX_DCHECK(column < columns.size(), "gather column out of range");
    const uint32_t ray = rays ? static_cast<uint32_t>(rays->size()) - 1 : 0;
    // Surfel clusters' weights can be negative (higher spherical harmonics).
    if (w.x != 0.0f || w.y != 0.0f || w.z != 0.0f) entries.push_back({column, ray, w});
  }
};

// What a pass reads: the cloud's radiance per column, and with directional lvoxels their
// source coefficients (GatherColumns::valuesInto).
struct GatherValues {
  std::vector<RGB> plain;
  std::vector<PaddedRGB> directional;
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
  //
  // With directional lvoxels (the cloud's lvoxel light has 9 coefficients) a row keeps its
  // rays apart: each ray's radiance depends on its direction, and a row's result is then
  // the spherical-harmonic projection of its rays' radiance, coefficients() values per row
  // (the first is the plain sum).
  template <class RecordRow>
  GatherOperator(const PointCloud& cloud, size_t rows, RecordRow&& record, int part = 0,
                 int parts = 1, const std::function<void(uint64_t)>& reserve = {});

  size_t rows() const { return rows_; }
  size_t entries() const;
  size_t memoryBytes() const;
  int coefficients() const { return columns_.coefficients; }
  // The values a pass reads, from the cloud as it stands, into `v`.
  void valuesInto(const PointCloud& cloud, const RGB& background, GatherValues& v) const {
    columns_.valuesInto(cloud, background, v.plain,
                        columns_.directional() ? &v.directional : nullptr);
  }
  // out[r * coefficients() + k] = coefficient k of row r (the sum of weight * value over
  // its entries, projected per ray where directional).
  void apply(const GatherValues& values, std::vector<RGB>& out) const;
  void apply(const std::vector<RGB>& values, std::vector<RGB>& out) const {
    apply(GatherValues{values, {}}, out);
  }
  // sink(r, const RGB* coefficients) for every row r, without a vector of all rows (it is
  // as large as the cloud): blocks of kRowsPerBlock rows in parallel, a block's rows in
  // order on one thread. Rows of blocks another part owns get 0.
  template <class Sink>
  void forEachRow(const GatherValues& values, Sink&& sink) const;
  static constexpr size_t kRowsPerBlock = 512;
  size_t blockCount() const { return blocks_.size(); }
  const GatherColumns& columns() const { return columns_; }

 private:
  // A block's weights are stored grey when all of them are (media with a colourless
  // extinction, and no media at all, give grey weights), as half floats relative to the
  // block's largest: a 2-byte weight instead of a 4-byte float (12 bytes for RGB), on the
  // operator, the largest memory item (issue 13: bytes per element). A half keeps 11 bits, so a
  // weight is rounded by at most 2^-11 of itself, or 2^-25 of the block's largest where it is below
  // 2^-14 of it (subnormal); the block's rows (neighbouring elements of one kind) share a scale.
  struct GreyWeights {
    const Imath::half* weight;
    float scale;
    float operator[](size_t e) const { return static_cast<float>(weight[e]) * scale; }
  };
  struct Block {
    std::vector<uint32_t> rowEnd;  // entries (directional: rays) of row k end at rowEnd[k]
    std::vector<uint32_t> column;
    std::vector<Imath::half> greyWeight;  // either this, times greyScale ...
    float greyScale = 1.0f;
    std::vector<RGB> colourWeight;   // ... or this holds the weights
    std::vector<uint32_t> rayEnd;    // directional: entries of ray j end at rayEnd[j] ...
    std::vector<Vec3> rayDirection;  // ... and it goes this way
  };
  // `rays`: the row's ray directions where the operator keeps rays apart, else null.
  static void appendMerged(std::vector<GatherEntry>& row, const std::vector<Vec3>* rays,
                           std::vector<GatherEntry>& entries, Block& block);
  static void store(const std::vector<GatherEntry>& entries, Block& block);
  // A directional column's radiance along one ray: shDot of its kShCoefficients padded
  // coefficients (directional columns have all of them) with the ray's Yhat, clamped at
  // zero; the Yhat are broadcast once per ray.
  class DirectionalDot {
   public:
    explicit DirectionalDot(const float* yhat);
    RGB operator()(const PaddedRGB* c) const;

   private:
#if defined(__SSE2__)
    __m128 yhat_[kShCoefficients];
#else
    float yhat_[kShCoefficients];
#endif
  };
  template <class Weight, class Sink>
  void applyBlock(const Block& block, const Weight& weight, size_t firstRow,
                  const GatherValues& values, Sink& sink) const;
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
    std::vector<Vec3> rays;
    TraversalScratch scratch;
    for (size_t r = begin; r < end; ++r) {
      row.clear();
      rays.clear();
      std::vector<Vec3>* directions = columns_.directional() ? &rays : nullptr;
      GatherRecorder recorder{cloud, columns_, row, directions};
      record(r, recorder, scratch);
      appendMerged(row, directions, entries, block);
    }
    store(entries, block);
    Progress::global().advance(end - begin);
    if (reserve)
      reserve(block.column.size() * sizeof(uint32_t) +
              block.greyWeight.size() * sizeof(Imath::half) +
              block.colourWeight.size() * sizeof(RGB) + block.rowEnd.size() * sizeof(uint32_t) +
              block.rayEnd.size() * sizeof(uint32_t) + block.rayDirection.size() * sizeof(Vec3));
  });
}

inline GatherOperator::DirectionalDot::DirectionalDot(const float* yhat) {
  for (int k = 0; k < kShCoefficients; ++k) {
#if defined(__SSE2__)
    yhat_[k] = _mm_set1_ps(yhat[k]);
#else
    yhat_[k] = yhat[k];
#endif
  }
}

inline RGB GatherOperator::DirectionalDot::operator()(const PaddedRGB* c) const {
#if defined(__SSE2__)
  // Two sums, the even and the odd coefficients: half the chain of dependent adds.
  static_assert(kShCoefficients % 2 == 1, "coefficient 0, then pairs");
  __m128 even = _mm_mul_ps(_mm_load_ps(c[0].c), yhat_[0]);
  __m128 odd = _mm_setzero_ps();
  for (int k = 1; k < kShCoefficients; k += 2) {
    odd = _mm_add_ps(odd, _mm_mul_ps(_mm_load_ps(c[k].c), yhat_[k]));
    even = _mm_add_ps(even, _mm_mul_ps(_mm_load_ps(c[k + 1].c), yhat_[k + 1]));
  }
  alignas(16) float v[4];
  _mm_store_ps(v, _mm_max_ps(_mm_add_ps(even, odd), _mm_setzero_ps()));
  return RGB(v[0], v[1], v[2]);
#else
  RGB sum(0.0f);
  for (int k = 0; k < kShCoefficients; ++k) sum += RGB(c[k].c[0], c[k].c[1], c[k].c[2]) * yhat_[k];
  return nonNegative(sum);
#endif
}

template <class Weight, class Sink>
void GatherOperator::applyBlock(const Block& block, const Weight& weight, size_t firstRow,
                                const GatherValues& values, Sink& sink) const {
  const std::vector<RGB>& plain = values.plain;
  uint32_t begin = 0;
  if (!columns_.directional()) {
    for (size_t k = 0; k < block.rowEnd.size(); ++k) {
      RGB sum(0.0f);
      for (uint32_t e = begin; e < block.rowEnd[k]; ++e) sum += plain[block.column[e]] * weight[e];
      sink(firstRow + k, &sum);
      begin = block.rowEnd[k];
    }
    return;
  }
  // Per ray: its radiance, with directional columns evaluated along it, projected on the
  // spherical harmonics of its direction.
  const int count = columns_.coefficients;
  LVOX_DCHECK(count == kShCoefficients, "directional columns carry every coefficient");
  const uint32_t first = columns_.firstDirectional();
  const PaddedRGB* coefficients = values.directional.data();
  uint32_t ray = 0;
  for (size_t k = 0; k < block.rowEnd.size(); ++k) {
    RGB out[kShCoefficients];
    std::fill(out, out + count, RGB(0.0f));
    for (; ray < block.rowEnd[k]; ++ray) {
      float yhat[kShCoefficients];
      shBasis(block.rayDirection[ray], kShCoefficients, yhat);
      const DirectionalDot along(yhat);
      RGB sum(0.0f);
      for (uint32_t e = begin; e < block.rayEnd[ray]; ++e) {
        const uint32_t c = block.column[e];
        const RGB value =
            c < first ? plain[c] : along(coefficients + static_cast<size_t>(c - first) * count);
        sum += value * weight[e];
      }
      begin = block.rayEnd[ray];
      for (int j = 0; j < count; ++j) out[j] += sum * yhat[j];
    }
    sink(firstRow + k, static_cast<const RGB*>(out));
  }
}

template <class Sink>
void GatherOperator::forEachRow(const GatherValues& values, Sink&& sink) const {
  tbb::parallel_for(size_t(0), blocks_.size(), [&](size_t b) {
    if (!owns(b)) {  // another process's rows: zero here, so the parts sum to the whole
      RGB zeros[kShCoefficients];  // (Imath's colours are not zeroed by default)
      std::fill(zeros, zeros + kShCoefficients, RGB(0.0f));
      for (size_t r = b * kRowsPerBlock; r < std::min(rows_, (b + 1) * kRowsPerBlock); ++r)
        sink(r, static_cast<const RGB*>(zeros));
      return;
    }
    const Block& block = blocks_[b];
    if (block.colourWeight.empty())
      applyBlock(block, GreyWeights{block.greyWeight.data(), block.greyScale}, b * kRowsPerBlock,
                 values, sink);
    else
      applyBlock(block, block.colourWeight, b * kRowsPerBlock, values, sink);
  });
}

}  // namespace lvox
