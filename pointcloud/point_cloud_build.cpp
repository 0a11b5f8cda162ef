// Octree construction: Morton sort of all element centres, then a breadth-first split on
// the Morton bits, one parallel pass per level, so node indices are deterministic.
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "pointcloud/element_bounds.h"
#include "pointcloud/point_cloud.h"
#include "src/core/check.h"

namespace lvox {

namespace {

constexpr uint32_t kMortonBits = kMaxOctreeDepth;  // per axis; 63-bit codes
constexpr uint32_t kMaxDepth = kMortonBits;

uint64_t spreadBits(uint32_t v) {
  uint64_t x = v & 0x1fffffu;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

struct MortonKey {
  uint64_t code;
  uint32_t element;  // surfels first, then lvoxels
  bool operator<(const MortonKey& o) const {
    return code != o.code ? code < o.code : element < o.element;
  }
};

// Root cube around the element centres: a cube keeps octants cubic (non-cubic cells give
// elongated, gappy clusters, as Aqsis notes).
struct MortonFrame {
  Vec3 lo;
  float scale;
  uint64_t code(const Vec3& p) const {
    uint32_t q[3];
    for (int a = 0; a < 3; ++a) {
      const float f = std::clamp((p[a] - lo[a]) * scale, 0.0f, float((1u << kMortonBits) - 1));
      q[a] = static_cast<uint32_t>(f);
    }
    return spreadBits(q[0]) << 2 | spreadBits(q[1]) << 1 | spreadBits(q[2]);
  }
};

MortonFrame mortonFrame(const SurfelSet& s, const LvoxelSet& l) {
  Bounds3 b;
  for (const Vec3& p : s.position) b.extend(p);
  for (const Vec3& p : l.position) b.extend(p);
  const Vec3 d = b.diagonal();
  const float extent = std::max({d.x, d.y, d.z, 1e-20f}) * 1.0001f;
  return {b.lo, float((1u << kMortonBits) - 1) / extent};
}

struct Range {
  uint32_t begin, end;
  uint32_t octant = 0;
};

// The octant's half of the parent cell; bit order as in MortonFrame::code (x, y, z).
Bounds3 childCell(const Bounds3& parent, uint32_t octant) {
  const Vec3 mid = parent.center();
  Bounds3 c = parent;
  for (int a = 0; a < 3; ++a) {
    if ((octant >> (2 - a)) & 1u)
      c.lo[a] = mid[a];
    else
      c.hi[a] = mid[a];
  }
  return c;
}

uint32_t childFlags(const OctreeNode& node) {
  return (node.isLeaf() ? OctreeChildren::kLeaf : 0u) |
         (node.surfelEnd > node.surfelBegin ? OctreeChildren::kSurfels : 0u) |
         (node.lvoxelEnd > node.lvoxelBegin ? OctreeChildren::kLvoxels : 0u);
}

float surfaceArea(const Bounds3& b) {
  const Vec3 d = b.diagonal();
  return d.x * d.y + d.y * d.z + d.z * d.x;
}

// The lanes of node n's wide block: its children, then, while they fit, the inner lane
// with surfels and the largest surface area replaced by its children (the likeliest to
// be opened by a ray). Lanes that hold lvoxels only are never opened by the search.
std::vector<uint32_t> wideLanes(const std::vector<OctreeNode>& nodes, uint32_t n) {
  std::vector<uint32_t> lanes;
  for (uint32_t c = 0; c < nodes[n].childCount; ++c) lanes.push_back(nodes[n].childBegin + c);
  for (;;) {
    size_t open = lanes.size();
    float largest = -1.0f;
    for (size_t l = 0; l < lanes.size(); ++l) {
      const OctreeNode& node = nodes[lanes[l]];
      if (node.isLeaf() || node.surfelEnd == node.surfelBegin ||
          lanes.size() - 1 + node.childCount > WideChildren::kWidth)
        continue;
      if (surfaceArea(node.bounds) > largest) {
        largest = surfaceArea(node.bounds);
        open = l;
      }
    }
    if (open == lanes.size()) return lanes;
    const OctreeNode& node = nodes[lanes[open]];
    lanes.erase(lanes.begin() + static_cast<std::ptrdiff_t>(open));
    for (uint32_t c = 0; c < node.childCount; ++c) lanes.push_back(node.childBegin + c);
  }
}

// Appends the wide block of inner node n and, depth first, those of its inner lanes with
// surfels; returns n's block index.
uint32_t buildWideBlocks(const std::vector<OctreeNode>& nodes, uint32_t n,
                         std::vector<WideChildren>& blocks) {
  const std::vector<uint32_t> lanes = wideLanes(nodes, n);
  const auto index = static_cast<uint32_t>(blocks.size());
  blocks.emplace_back();
  for (uint32_t c = 0; c < WideChildren::kWidth; ++c) {
    const bool used = c < lanes.size();
    const Bounds3 box = used ? nodes[lanes[c]].bounds : Bounds3{};
    uint32_t ref = 0, surfelEnd = 0;
    if (used) {
      const OctreeNode& node = nodes[lanes[c]];
      ref = childFlags(node);
      surfelEnd = node.surfelEnd;
      if (node.isLeaf())
        ref |= node.surfelBegin;
      else if (node.surfelEnd > node.surfelBegin)
        ref |= buildWideBlocks(nodes, lanes[c], blocks);
    }
    WideChildren& b = blocks[index];  // after the recursion, which may reallocate
    for (int a = 0; a < 3; ++a) {
      b.lo[a][c] = box.lo[a];
      b.hi[a][c] = box.hi[a];
    }
    b.ref[c] = ref;
    b.surfelEnd[c] = surfelEnd;
  }
  return index;
}

}  // namespace

PointCloud::PointCloud(SurfelSet surfels, LvoxelSet lvoxels, const OctreeSettings& settings)
    : lvoxels_(std::move(lvoxels)), keepSurfelClusters_(settings.surfelClusters) {
  build(std::move(surfels), settings);
  computeBounds();
  assignLvoxelClusters();
  // The aggregates grow the node bounds to hold the surfel cluster covers, which depend on
  // the geometry only: the bounds are final after this update, and the traversal layout
  // copies them. (Lvoxel cluster boxes lie inside the bounds already.)
  updateAggregates();
  buildTraversalLayout();
  if (!keepSurfelClusters_) std::vector<Bounds3>().swap(cells_);  // only the covers use them
}

void PointCloud::assignLvoxelClusters() {
  lvoxelClusterOf_.assign(nodes_.size(), kNoLvoxelCluster);
  uint32_t count = 0;
  for (size_t n = 0; n < nodes_.size(); ++n)
    if (nodes_[n].lvoxelEnd > nodes_[n].lvoxelBegin) lvoxelClusterOf_[n] = count++;
  lvoxelClusterCount_ = count;
}

bool PointCloud::traversalLayoutMatchesNodes() const {
  std::vector<WideChildren> wide;
  if (!nodes_.empty() && !nodes_[0].isLeaf()) buildWideBlocks(nodes_, 0, wide);
  if (wide.size() != wideBlocks_.size() ||
      !std::equal(wide.begin(), wide.end(), wideBlocks_.begin(),
                  [](const WideChildren& a, const WideChildren& b) {
                    return std::memcmp(&a, &b, sizeof(WideChildren)) == 0;
                  }))
    return false;
  for (uint32_t i = 0; i < nodes_.size(); ++i) {
    const OctreeNode& node = nodes_[i];
    if (node.isLeaf()) continue;
    const OctreeChildren& b = childBlocks_[traversalNodes_[i].ref & OctreeChildren::kIndexMask];
    for (uint32_t c = 0; c < node.childCount; ++c) {
      const Bounds3& box = nodes_[node.childBegin + c].bounds;
      for (int a = 0; a < 3; ++a)
        if (b.lo[a][c] != box.lo[a] || b.hi[a][c] != box.hi[a]) return false;
    }
  }
  return true;
}

void PointCloud::build(SurfelSet surfels, const OctreeSettings& settings) {
  const auto ns = static_cast<uint32_t>(surfels.size());
  const auto n = ns + static_cast<uint32_t>(lvoxels_.size());
  if (n == 0) return;
  const MortonFrame frame = mortonFrame(surfels, lvoxels_);
  std::vector<MortonKey> keys(n);
  tbb::parallel_for(uint32_t(0), n, [&](uint32_t e) {
    keys[e] = {frame.code(e < ns ? surfels.position[e] : lvoxels_.position[e - ns]), e};
  });
  tbb::parallel_sort(keys.begin(), keys.end());

  // Reorder both sets along the curve; surfelsBefore[k] = surfels among keys[0, k).
  std::vector<uint32_t> surfelOrder, lvoxelOrder;
  std::vector<uint32_t> surfelsBefore(n + 1, 0);
  surfelOrder.reserve(ns);
  lvoxelOrder.reserve(n - ns);
  for (uint32_t k = 0; k < n; ++k) {
    const bool isSurfel = keys[k].element < ns;
    if (isSurfel)
      surfelOrder.push_back(keys[k].element);
    else
      lvoxelOrder.push_back(keys[k].element - ns);
    surfelsBefore[k + 1] = surfelsBefore[k] + (isSurfel ? 1 : 0);
  }
  surfels.permute(surfelOrder);
  surfels_ = CloudSurfels(std::move(surfels), clips_);
  lvoxels_.permute(lvoxelOrder);

  const uint32_t leafSize = std::max(1u, settings.leafSize);
  const uint32_t maxDepth = std::min(settings.maxDepth, kMaxDepth);
  auto makeNode = [&](Range r) {
    OctreeNode node;
    node.surfelBegin = surfelsBefore[r.begin];
    node.surfelEnd = surfelsBefore[r.end];
    node.lvoxelBegin = r.begin - surfelsBefore[r.begin];
    node.lvoxelEnd = r.end - surfelsBefore[r.end];
    return node;
  };

  std::vector<Range> ranges{{0, n}};
  nodes_.assign(1, makeNode(ranges[0]));
  Bounds3 root;
  root.lo = frame.lo;
  root.hi = frame.lo + Vec3(1.0f, 1.0f, 1.0f) * (float(1u << kMortonBits) / frame.scale);
  cells_.assign(1, root);
  levelBegin_.assign(1, 0);
  uint32_t begin = 0, end = 1;
  for (uint32_t depth = 0; begin < end; ++depth) {
    levelBegin_.push_back(end);
    const uint32_t count = end - begin;
    std::vector<std::array<Range, 8>> children(count);
    std::vector<uint32_t> childCounts(count, 0);
    const int shift = 3 * static_cast<int>(kMortonBits - 1 - std::min(depth, kMortonBits - 1));
    tbb::parallel_for(uint32_t(0), count, [&](uint32_t i) {
      const Range r = ranges[begin + i];
      if (r.end - r.begin <= leafSize || depth >= maxDepth) return;
      // Codes in a node share all bits above `shift`, so the octants are sorted runs.
      uint32_t lo = r.begin;
      for (uint64_t octant = 0; octant < 8 && lo < r.end; ++octant) {
        const auto it = std::partition_point(
            keys.begin() + lo, keys.begin() + r.end,
            [&](const MortonKey& k) { return ((k.code >> shift) & 7u) <= octant; });
        const auto hi = static_cast<uint32_t>(it - keys.begin());
        if (hi > lo) children[i][childCounts[i]++] = {lo, hi, static_cast<uint32_t>(octant)};
        lo = hi;
      }
    });
    for (uint32_t i = 0; i < count; ++i) {
      if (childCounts[i] == 0) continue;
      nodes_[begin + i].childBegin = static_cast<uint32_t>(nodes_.size());
      nodes_[begin + i].childCount = static_cast<uint8_t>(childCounts[i]);
      for (uint32_t c = 0; c < childCounts[i]; ++c) {
        ranges.push_back(children[i][c]);
        nodes_.push_back(makeNode(children[i][c]));
        cells_.push_back(childCell(cells_[begin + i], children[i][c].octant));
      }
    }
    begin = end;
    end = static_cast<uint32_t>(nodes_.size());
  }
}

void PointCloud::computeBounds() {
  if (nodes_.empty()) return;
  for (size_t level = levelBegin_.size() - 1; level-- > 0;) {
    tbb::parallel_for(levelBegin_[level], levelBegin_[level + 1], [&](uint32_t i) {
      OctreeNode& node = nodes_[i];
      Bounds3 b;
      if (node.isLeaf()) {
        for (uint32_t s = node.surfelBegin; s < node.surfelEnd; ++s)
          b.extend(diskBounds(surfels_.disks()[s]));
        for (uint32_t l = node.lvoxelBegin; l < node.lvoxelEnd; ++l)
          b.extend(lvoxelBounds(lvoxels_, l));
      } else {
        for (uint32_t c = 0; c < node.childCount; ++c) b.extend(nodes_[node.childBegin + c].bounds);
      }
      node.bounds = b;
    });
  }
}

void PointCloud::buildTraversalLayout() {
  const auto n = static_cast<uint32_t>(nodes_.size());
  if (n > OctreeChildren::kIndexMask || surfels_.size() > OctreeChildren::kIndexMask)
    throw std::length_error("point cloud: too many nodes or surfels for the traversal layout");
  traversalNodes_.assign(n, TraversalNode{});
  if (n == 0) return;
  uint32_t blocks = 0;
  for (uint32_t i = 0; i < n; ++i) {
    const OctreeNode& node = nodes_[i];
    TraversalNode& t = traversalNodes_[i];
    t.ref = childFlags(node) | (node.isLeaf() ? node.surfelBegin : blocks++);
    t.surfelEnd = node.surfelEnd;
    t.first = node.isLeaf() ? node.lvoxelBegin : node.childBegin;
    t.lvoxelEnd = node.lvoxelEnd;
  }
  childBlocks_.assign(blocks, OctreeChildren{});
  tbb::parallel_for(uint32_t(0), n, [&](uint32_t i) {
    const OctreeNode& node = nodes_[i];
    if (node.isLeaf()) return;
    OctreeChildren& b = childBlocks_[traversalNodes_[i].ref & OctreeChildren::kIndexMask];
    for (uint32_t c = 0; c < 8; ++c) {
      // Unused lanes have ref 0, which masks them; give them an empty box all the same.
      const Bounds3 box = c < node.childCount ? nodes_[node.childBegin + c].bounds : Bounds3{};
      for (int a = 0; a < 3; ++a) {
        b.lo[a][c] = box.lo[a];
        b.hi[a][c] = box.hi[a];
      }
      const TraversalNode used =
          c < node.childCount ? traversalNodes_[node.childBegin + c] : TraversalNode{};
      b.ref[c] = used.ref;
      b.surfelEnd[c] = used.surfelEnd;
    }
  });
  wideBlocks_.clear();
  if (!nodes_[0].isLeaf()) buildWideBlocks(nodes_, 0, wideBlocks_);
  cubes_.resize(lvoxels_.size());
  for (size_t i = 0; i < lvoxels_.size(); ++i)
    cubes_[i] = {lvoxels_.position[i], lvoxels_.halfSize[i]};
  lattice_ = LvoxelLattice::of(cubes_);
  // useCluster's radius, as it computes it, of every node it could make a cluster of on
  // an lvoxel-only ray (with lvoxels, more than one element): the bounds are final here.
  minLvoxelClusterRadius_ = kInf;
  for (const OctreeNode& node : nodes_)
    if (node.lvoxelEnd > node.lvoxelBegin && node.elementCount() > 1)
      minLvoxelClusterRadius_ =
          std::min(minLvoxelClusterRadius_, std::sqrt(0.25f * node.bounds.diagonal().length2()));
}

float PointCloud::lvoxelClusterFreeReach(float maxSolidAngle) const {
  if (!(maxSolidAngle > 0.0f)) return kInf;
  // A node of radius r is a cluster only when its centre is farther than k r from the
  // origin (useCluster: d > 2 r and pi r^2 < maxSolidAngle d^2), so every point of it is
  // farther than (k - 1) r; the factor leaves room for useCluster's roundings.
  const float k = std::max(2.0f, std::sqrt(kPi / maxSolidAngle));
  return (k - 1.0f) * minLvoxelClusterRadius_ * 0.9999f;
}

uint32_t PointCloud::searchRoot(uint32_t& surfelEnd) const {
  const OctreeNode& root = nodes_[0];
  surfelEnd = root.surfelEnd;
  return childFlags(root) | (root.isLeaf() ? root.surfelBegin : 0u);  // block 0 is the root's
}

PointCloudMemory PointCloud::memory() const {
  PointCloudMemory m;
  m.surfelBytes = surfels_.memoryBytes();
  m.lvoxelBytes = lvoxels_.memoryBytes();
  m.octreeBytes = nodes_.size() * sizeof(OctreeNode) + cells_.size() * sizeof(Bounds3) +
                  surfelClusters_.size() * sizeof(SurfelCluster) +
                  lvoxelClusters_.size() * sizeof(LvoxelCluster) +
                  lvoxelClusterCoefficients_.size() * sizeof(RGB) +
                  lvoxelClusterOf_.size() * sizeof(uint32_t) +
                  levelBegin_.size() * sizeof(uint32_t) + traversalBytes();
  return m;
}

size_t PointCloud::traversalBytes() const {
  return childBlocks_.size() * sizeof(OctreeChildren) + wideBlocks_.size() * sizeof(WideChildren) +
         traversalNodes_.size() * sizeof(TraversalNode) + clips_.size() * sizeof(DiskClip) +
         cubes_.size() * sizeof(CubeElement) + (lattice_ ? lattice_->memoryBytes() : 0);
}

}  // namespace lvox
