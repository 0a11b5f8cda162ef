#include "pointcloud/gather_operator.h"

namespace lvox {

GatherColumns::GatherColumns(const PointCloud& cloud)
    : surfels(cloud.surfels().size()),
      lvoxels(cloud.lvoxels().size()),
      surfelClusters(cloud.surfelClusters().size()),
      lvoxelClusters(cloud.lvoxelClusters().size()) {}

std::vector<RGB> GatherColumns::values(const PointCloud& cloud,
                                       const RGB& backgroundRadiance) const {
  std::vector<RGB> v(size());
  const SurfelSet& s = cloud.surfels();
  for (size_t i = 0; i < surfels; ++i) {
    v[surfel(index(i), true)] = s.radianceFront[i];
    v[surfel(index(i), false)] = s.radianceBack[i];
  }
  for (size_t i = 0; i < lvoxels; ++i) v[lvoxel(index(i))] = cloud.lvoxels().sourceRadiance(i);
  for (size_t n = 0; n < surfelClusters; ++n) {
    v[surfelCluster(index(n), true)] = cloud.surfelClusters()[n].radianceFront;
    v[surfelCluster(index(n), false)] = cloud.surfelClusters()[n].radianceBack;
  }
  for (size_t n = 0; n < lvoxelClusters; ++n)
    v[lvoxelCluster(index(n))] = cloud.lvoxelClusters()[n].sourceRadiance;
  v[background()] = backgroundRadiance;
  return v;
}

// Rays of one gather often reach the same element: one entry per column.
void GatherOperator::appendMerged(std::vector<GatherEntry>& row, Block& block) {
  std::sort(row.begin(), row.end(),
            [](const GatherEntry& a, const GatherEntry& b) { return a.column < b.column; });
  for (const GatherEntry& e : row) {
    const size_t rowBegin = block.rowEnd.empty() ? 0 : block.rowEnd.back();
    if (block.entries.size() > rowBegin && block.entries.back().column == e.column)
      block.entries.back().weight += e.weight;
    else
      block.entries.push_back(e);
  }
  block.rowEnd.push_back(static_cast<uint32_t>(block.entries.size()));
}

size_t GatherOperator::entries() const {
  size_t n = 0;
  for (const Block& b : blocks_) n += b.entries.size();
  return n;
}

size_t GatherOperator::memoryBytes() const {
  size_t bytes = 0;
  for (const Block& b : blocks_)
    bytes += b.entries.capacity() * sizeof(GatherEntry) + b.rowEnd.capacity() * sizeof(uint32_t);
  return bytes;
}

void GatherOperator::apply(const std::vector<RGB>& values, std::vector<RGB>& out) const {
  out.resize(rows_);
  tbb::parallel_for(size_t(0), blocks_.size(), [&](size_t b) {
    const Block& block = blocks_[b];
    if (!owns(b)) {
      const size_t begin = b * kRowsPerBlock, end = std::min(rows_, begin + kRowsPerBlock);
      std::fill(out.begin() + static_cast<std::ptrdiff_t>(begin),
                out.begin() + static_cast<std::ptrdiff_t>(end), RGB(0.0f));
      return;
    }
    uint32_t begin = 0;
    for (size_t k = 0; k < block.rowEnd.size(); ++k) {
      RGB sum(0.0f);
      for (uint32_t e = begin; e < block.rowEnd[k]; ++e)
        sum += block.entries[e].weight * values[block.entries[e].column];
      out[b * kRowsPerBlock + k] = sum;
      begin = block.rowEnd[k];
    }
  });
}

}  // namespace lvox
