#include "pointcloud/gather_operator.h"

#include <cmath>

namespace lvox {

GatherColumns::GatherColumns(const PointCloud& cloud)
    : surfels(cloud.surfels().size()),
      lvoxels(cloud.lvoxels().size()),
      surfelClusters(cloud.surfelClusters().size()),
      lvoxelClusters(cloud.lvoxelClusters().size()),
      coefficients(cloud.lvoxels().light.coefficients()) {}

std::vector<RGB> GatherColumns::values(const PointCloud& cloud,
                                       const RGB& backgroundRadiance) const {
  std::vector<RGB> v;
  valuesInto(cloud, backgroundRadiance, v);
  return v;
}

void GatherColumns::valuesInto(const PointCloud& cloud, const RGB& backgroundRadiance,
                               std::vector<RGB>& v, std::vector<PaddedRGB>* directional) const {
  v.resize(size());
  const CloudSurfels& s = cloud.surfels();
  for (size_t i = 0; i < surfels; ++i) {
    v[surfel(index(i), true)] = s.radianceFront[i];
    v[surfel(index(i), false)] = s.radianceBack[i];
  }
  for (size_t i = 0; i < lvoxels; ++i) v[lvoxel(index(i))] = cloud.lvoxels().sourceRadiance(i);
  for (size_t n = 0; n < surfelClusters; ++n)
    for (int k = 0; k < kShCoefficients; ++k)
      v[surfelCluster(index(n), k)] = cloud.surfelClusters()[n].power[k];
  for (size_t n = 0; n < lvoxelClusters; ++n)
    v[lvoxelCluster(index(n))] = cloud.lvoxelClusters()[n].sourceRadiance;
  v[background()] = backgroundRadiance;
  if (!directional || !this->directional()) return;
  const auto count = static_cast<size_t>(coefficients);
  directional->resize((lvoxels + lvoxelClusters) * count);
  auto pad = [&](size_t column, const RGB* c) {
    PaddedRGB* out = directional->data() + column * count;
    for (size_t k = 0; k < count; ++k) out[k] = PaddedRGB{{c[k].x, c[k].y, c[k].z, 0.0f}};
  };
  RGB source[kShCoefficients];
  for (size_t i = 0; i < lvoxels; ++i) {
    cloud.lvoxels().sourceCoefficients(i, source);
    pad(i, source);
  }
  for (size_t n = 0; n < lvoxelClusters; ++n)
    pad(lvoxels + n, cloud.lvoxelClusterCoefficients(index(n)));
}

// Rays of one gather often reach the same element: one entry per column (per ray and
// column where the operator keeps rays apart; rays that picked up nothing are dropped).
void GatherOperator::appendMerged(std::vector<GatherEntry>& row, const std::vector<Vec3>* rays,
                                  std::vector<GatherEntry>& entries, Block& block) {
  std::sort(row.begin(), row.end(), [](const GatherEntry& a, const GatherEntry& b) {
    return a.ray != b.ray ? a.ray < b.ray : a.column < b.column;
  });
  const size_t rowBegin = entries.size();
  for (const GatherEntry& e : row) {
    const bool sameRay = entries.size() > rowBegin && entries.back().ray == e.ray;
    if (sameRay && entries.back().column == e.column) {
      entries.back().weight += e.weight;
      continue;
    }
    if (rays && !sameRay && entries.size() > rowBegin) {  // the previous ray ends
      block.rayEnd.push_back(static_cast<uint32_t>(entries.size()));
      block.rayDirection.push_back((*rays)[entries.back().ray]);
    }
    entries.push_back(e);
  }
  if (rays) {
    if (entries.size() > rowBegin) {
      block.rayEnd.push_back(static_cast<uint32_t>(entries.size()));
      block.rayDirection.push_back((*rays)[entries.back().ray]);
    }
    block.rowEnd.push_back(static_cast<uint32_t>(block.rayEnd.size()));
  } else {
    block.rowEnd.push_back(static_cast<uint32_t>(entries.size()));
  }
}

void GatherOperator::store(const std::vector<GatherEntry>& entries, Block& block) {
  const bool grey = std::all_of(entries.begin(), entries.end(), [](const GatherEntry& e) {
    return e.weight.x == e.weight.y && e.weight.x == e.weight.z;
  });
  block.column.resize(entries.size());
  if (grey) {
    float largest = 0.0f;
    for (const GatherEntry& e : entries) largest = std::max(largest, std::abs(e.weight.x));
    block.greyScale = largest > 0.0f ? largest : 1.0f;
    block.greyWeight.resize(entries.size());
  } else {
    block.colourWeight.resize(entries.size());
  }
  for (size_t e = 0; e < entries.size(); ++e) {
    block.column[e] = entries[e].column;
    if (grey)
      block.greyWeight[e] = Imath::half(entries[e].weight.x / block.greyScale);
    else
      block.colourWeight[e] = entries[e].weight;
  }
  block.rowEnd.shrink_to_fit();
  block.rayEnd.shrink_to_fit();
  block.rayDirection.shrink_to_fit();
}

size_t GatherOperator::entries() const {
  size_t n = 0;
  for (const Block& b : blocks_) n += b.column.size();
  return n;
}

size_t GatherOperator::memoryBytes() const {
  size_t bytes = 0;
  for (const Block& b : blocks_)
    bytes += b.column.capacity() * sizeof(uint32_t) +
             b.greyWeight.capacity() * sizeof(Imath::half) +
             b.colourWeight.capacity() * sizeof(RGB) + b.rowEnd.capacity() * sizeof(uint32_t) +
             b.rayEnd.capacity() * sizeof(uint32_t) + b.rayDirection.capacity() * sizeof(Vec3);
  return bytes;
}

void GatherOperator::apply(const GatherValues& values, std::vector<RGB>& out) const {
  const auto count = static_cast<size_t>(coefficients());
  out.resize(rows_ * count);
  forEachRow(values, [&](size_t row, const RGB* c) { std::copy(c, c + count, &out[row * count]); });
}

}  // namespace lvox
