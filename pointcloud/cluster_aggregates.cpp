// Bottom-up cluster aggregates (the level of detail used by distant gathers).
#include <tbb/parallel_for.h>

#include "pointcloud/point_cloud.h"

namespace lvox {

namespace {

// Sums of a cluster's surfels (or child clusters), weighted by their represented area.
struct SurfelSums {
  Bounds3 cover;
  float diskArea = 0.0f;
  Vec3 weightedPosition{0, 0, 0};
  float area = 0.0f;
  float moment[6] = {0, 0, 0, 0, 0, 0};
  SurfelCluster sh;  // openArea and power, summed

  // A surfel of represented area a, unit normal n, radiance lf / lb of its sides, and
  // `enclosed` sides (SurfelSet::enclosedSides bits).
  void addSurfel(const Vec3& p, float a, const Vec3& n, const RGB& lf, const RGB& lb,
                 uint8_t enclosed) {
    if (!(a > 0.0f)) return;
    weightedPosition += p * a;
    area += a;
    const float m[6] = {n.x * n.x, n.y * n.y, n.z * n.z, n.x * n.y, n.x * n.z, n.y * n.z};
    for (int k = 0; k < 6; ++k) moment[k] += a * m[k];
    if (!(enclosed & 1u)) addSide(n, a, lf);
    if (!(enclosed & 2u)) addSide(-n, a, lb);
  }
  void addSide(const Vec3& m, float a, const RGB& radiance) {
    float c[kShCoefficients];
    clampedCosineCoefficients(m, c);
    for (int k = 0; k < kShCoefficients; ++k) {
      sh.openArea[k] += a * c[k];
      sh.power[k] += radiance * (a * c[k]);
    }
  }
  void addCluster(const SurfelCluster& c) {
    if (!(c.area > 0.0f)) return;
    weightedPosition += c.centroid * c.area;
    area += c.area;
    for (int k = 0; k < 6; ++k) moment[k] += c.moment[k] * c.area;
    for (int k = 0; k < kShCoefficients; ++k) {
      sh.openArea[k] += c.openArea[k];
      sh.power[k] += c.power[k];
    }
    cover.extend(c.cover);
    diskArea += c.diskArea;
  }
  SurfelCluster finish() const {
    if (area <= 0.0f) return SurfelCluster{};
    SurfelCluster c = sh;
    c.cover = cover;
    c.diskArea = diskArea;
    c.centroid = weightedPosition / area;
    c.area = area;
    for (int k = 0; k < 6; ++k) c.moment[k] = moment[k] / area;
    return c;
  }
};

// Bounds of a square of side `side` in the plane normal to n, approximated like a disk's
// (half extent side/2 * sqrt(1 - n_a^2) per axis): exact for axis-aligned surfaces.
Bounds3 squareBounds(const Vec3& p, const Vec3& n, float side) {
  const float h = 0.5f * side;
  const Vec3 e(h * std::sqrt(std::max(0.0f, 1.0f - n.x * n.x)),
               h * std::sqrt(std::max(0.0f, 1.0f - n.y * n.y)),
               h * std::sqrt(std::max(0.0f, 1.0f - n.z * n.z)));
  Bounds3 b;
  b.lo = p - e;
  b.hi = p + e;
  return b;
}

struct LvoxelSums {
  Bounds3 box;
  RGB crossSection{0, 0, 0};  // sum sigma_t V
  RGB weightedSource[kShCoefficients];

  LvoxelSums() { std::fill(weightedSource, weightedSource + kShCoefficients, RGB(0.0f)); }

  // An lvoxel's cube (or a child cluster's box) of cross-section xs.
  void add(const Bounds3& b, const RGB& xs, const RGB* source, int count) {
    box.extend(b);
    crossSection += xs;
    for (int k = 0; k < count; ++k) weightedSource[k] += xs * source[k];
  }
  // The cluster, and the cross-section-weighted mean of the sources' coefficients into
  // `source` (count of them).
  LvoxelCluster finish(RGB* source, int count) const {
    LvoxelCluster c;
    for (int k = 0; k < count; ++k) source[k] = RGB(0.0f);
    const Vec3 e = box.diagonal();
    const float volume = e.x * e.y * e.z;
    if (!(volume > 0.0f)) return c;
    c.box = box;
    c.sigmaT = crossSection / volume;
    for (int k = 0; k < count; ++k)
      for (int ch = 0; ch < 3; ++ch)
        source[k][ch] = crossSection[ch] > 0.0f ? weightedSource[k][ch] / crossSection[ch] : 0.0f;
    c.sourceRadiance = source[0];
    return c;
  }
};

}  // namespace

void PointCloud::updateAggregates() {
  const bool surfelClusters = keepSurfelClusters_;
  surfelClusters_.assign(surfelClusters ? nodes_.size() : 0, SurfelCluster{});
  lvoxelClusters_.assign(lvoxelClusterCount_, LvoxelCluster{});
  // Directional lvoxels: every cluster's coefficients (the first is sourceRadiance).
  const int count = lvoxels_.light.coefficients();
  lvoxelClusterCoefficients_.assign(count > 1 ? size_t(lvoxelClusterCount_) * kShCoefficients : 0,
                                    RGB(0.0f));
  if (nodes_.empty()) return;
  for (size_t level = levelBegin_.size() - 1; level-- > 0;) {
    tbb::parallel_for(levelBegin_[level], levelBegin_[level + 1], [&](uint32_t i) {
      const OctreeNode& node = nodes_[i];
      SurfelSums ss;
      LvoxelSums ls;
      if (node.isLeaf()) {
        for (uint32_t s = node.surfelBegin; surfelClusters && s < node.surfelEnd; ++s) {
          const float a = surfels_.representedArea(s);
          ss.addSurfel(surfels_.position(s), a, surfels_.normal(s), surfels_.radianceFront[s],
                       surfels_.radianceBack[s], surfels_.enclosedSides(s));
          ss.cover.extend(
              squareBounds(surfels_.position(s), surfels_.normal(s), 2.0f * std::sqrt(a)));
          ss.diskArea += kPi * surfels_.radius(s) * surfels_.radius(s);
        }
        for (uint32_t l = node.lvoxelBegin; l < node.lvoxelEnd; ++l) {
          RGB source[kShCoefficients];
          lvoxels_.sourceCoefficients(l, source);
          const float h = lvoxels_.halfSize[l];
          Bounds3 cube;
          cube.lo = lvoxels_.position[l] - Vec3(h, h, h);
          cube.hi = lvoxels_.position[l] + Vec3(h, h, h);
          ls.add(cube, lvoxels_.sigmaT(l) * lvoxels_.volume(l), source, count);
        }
      } else {
        for (uint32_t c = node.childBegin; c < node.childBegin + node.childCount; ++c) {
          if (surfelClusters) ss.addCluster(surfelClusters_[c]);
          const uint32_t k = lvoxelClusterOf_[c];
          if (k == kNoLvoxelCluster || lvoxelClusters_[k].empty()) continue;
          const LvoxelCluster& lc = lvoxelClusters_[k];
          const Vec3 e = lc.box.diagonal();
          ls.add(lc.box, lc.sigmaT * (e.x * e.y * e.z), lvoxelClusterCoefficients(k), count);
        }
      }
      if (surfelClusters && node.isLeaf()) {
        // Clip the squares to the node's cell: cover boxes of one level then tile a
        // surface instead of overlapping where neighbouring squares stick out.
        const Bounds3& cell = cells_[i];
        for (int a = 0; a < 3; ++a) {
          ss.cover.lo[a] = std::max(ss.cover.lo[a], cell.lo[a]);
          ss.cover.hi[a] = std::min(ss.cover.hi[a], cell.hi[a]);
        }
      }
      if (surfelClusters) surfelClusters_[i] = ss.finish();
      // The traversal enters a node only through its bounds: they must hold the cluster
      // proxies too (the cover box may reach past the disks into the cell's gaps; the
      // lvoxel box is the lvoxels' bounds, inside already). Bounds only grow, so repeated
      // updates are idempotent.
      OctreeNode& mutableNode = nodes_[i];
      if (ss.area > 0.0f) mutableNode.bounds.extend(ss.cover);
      for (uint32_t c = node.childBegin; c < node.childBegin + node.childCount; ++c)
        mutableNode.bounds.extend(nodes_[c].bounds);
      const uint32_t k = lvoxelClusterOf_[i];
      if (k == kNoLvoxelCluster) return;
      RGB source[kShCoefficients];
      lvoxelClusters_[k] = ls.finish(source, count);
      if (count > 1)
        std::copy(source, source + kShCoefficients,
                  &lvoxelClusterCoefficients_[size_t(k) * kShCoefficients]);
    });
  }
}

}  // namespace lvox
