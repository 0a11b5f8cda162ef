#pragma once
// Front-to-back traversal of the point cloud along one ray, templated on a visitor.
//
// Best-first order: one min-heap holds octree nodes keyed by the ray's entry distance
// into their loose bounds, and element hits keyed by their hit distance. A child's
// bounds lie inside its parent's and an element inside its leaf, so keys never drop
// below the key just popped: the visitor sees elements in exactly non-decreasing t,
// even where loose bounds overlap (ordering children by centre distance, as Aqsis does,
// gets this wrong when elements stick out of their cells). Surfels are opaque: pushing
// a surfel hit shrinks tmax, so nothing behind it is tested, and visiting it ends the
// traversal.
//
// Visitor interface (no virtual calls):
//   void surfel(uint32_t i, float t, bool front);       // opaque, ends traversal
//   bool lvoxel(uint32_t i, float t0, float t1);        // false stops
//   bool surfelCluster(uint32_t node, float t, bool front, float coverage);  // partial
//   bool lvoxelCluster(uint32_t node, float t0, float t1);  // false stops
#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "pointcloud/point_cloud.h"
#include "pointcloud/ray_element.h"

namespace lvox {

struct TraversalOptions {
  // A node whose bounding sphere (radius R, centre at distance d from the ray origin,
  // d > 2R) subtends pi R^2 / d^2 < maxSolidAngle steradians is used as its cluster
  // proxies instead of being opened. 0 disables clusters (exact traversal).
  float maxSolidAngle = 0.0f;
  // The same for nodes that hold lvoxels only (the larger of the two applies). Lvoxel
  // proxies conserve the extinction cross-section exactly, while surfel proxies average
  // the two sides of closed geometry, so media can use clusters where surfaces do not.
  float maxLvoxelSolidAngle = 0.0f;
  // False: surfels and their clusters are not tested (lvoxels only), for rays whose
  // surface hit comes from ray tracing the real geometry.
  bool surfels = true;
};

struct TraversalStats {
  uint64_t nodesPopped = 0;
  uint64_t elementsTested = 0;
  uint64_t elementsVisited = 0;
};

enum class HitKind : uint8_t { Node, Surfel, Lvoxel, SurfelCluster, LvoxelCluster };

struct TraversalEntry {
  float key;     // ordering distance
  float t0, t1;  // hit interval (t0 = t1 for disks; t1 = coverage for surfel clusters)
  uint32_t id;   // node, surfel or lvoxel index
  HitKind kind;
  bool front;
  bool operator>(const TraversalEntry& o) const { return key > o.key; }
};

// Reusable heap storage: one per thread (or per gather), never shared between threads.
struct TraversalScratch {
  std::vector<TraversalEntry> heap;
  TraversalStats stats;
};

namespace detail {

inline void pushEntry(std::vector<TraversalEntry>& heap, const TraversalEntry& e) {
  heap.push_back(e);
  std::push_heap(heap.begin(), heap.end(), std::greater<>{});
}

inline bool useCluster(const OctreeNode& node, const Ray& ray, const TraversalOptions& o) {
  const float maxAngle = o.surfels && node.surfelEnd > node.surfelBegin
                             ? o.maxSolidAngle
                             : std::max(o.maxSolidAngle, o.maxLvoxelSolidAngle);
  if (maxAngle <= 0.0f || node.elementCount() <= 1) return false;
  const float r2 = 0.25f * node.bounds.diagonal().length2();
  const float d2 = (node.bounds.center() - ray.origin).length2();
  return d2 > 4.0f * r2 && kPi * r2 < maxAngle * d2;
}

inline void pushClusters(const PointCloud& pc, uint32_t n, float entry, const Ray& ray,
                         bool surfels, std::vector<TraversalEntry>& heap) {
  const OctreeNode& node = pc.nodes()[n];
  if (node.lvoxelEnd > node.lvoxelBegin) {
    const LvoxelCluster& c = pc.lvoxelClusters()[n];
    float t0, t1;
    if (intersectCube(ray, c.centroid, c.halfSize, t0, t1))
      pushEntry(heap, {std::max(t0, entry), t0, t1, n, HitKind::LvoxelCluster, false});
  }
  if (surfels && node.surfelEnd > node.surfelBegin) {
    const SurfelCluster& c = pc.surfelClusters()[n];
    float t0, t1;
    if (c.cover.intersect(ray, t0, t1)) {
      const float coverage = c.coverage(ray.dir);
      if (coverage > 0.0f)
        pushEntry(heap, {std::max(t0, entry), t0, coverage, n, HitKind::SurfelCluster,
                         dot(c.axis, ray.dir) < 0.0f});
    }
  }
}

inline void pushLeafElements(const PointCloud& pc, const OctreeNode& node, Ray& ray, bool surfels,
                             TraversalScratch& s) {
  const SurfelSet& sf = pc.surfels();
  for (uint32_t i = node.surfelBegin; surfels && i < node.surfelEnd; ++i) {
    ++s.stats.elementsTested;
    float t;
    bool front;
    if (intersectDisk(ray, sf.position[i], sf.normal[i], sf.radius[i], sf.clip[i], t, front) &&
        !(sf.enclosedSides[i] & (front ? 1u : 2u))) {
      pushEntry(s.heap, {t, t, t, i, HitKind::Surfel, front});
      ray.tmax = t;  // opaque: everything behind is hidden
    }
  }
  const LvoxelSet& lv = pc.lvoxels();
  for (uint32_t i = node.lvoxelBegin; i < node.lvoxelEnd; ++i) {
    ++s.stats.elementsTested;
    float t0, t1;
    if (intersectCube(ray, lv.position[i], lv.halfSize[i], t0, t1))
      pushEntry(s.heap, {t0, t0, t1, i, HitKind::Lvoxel, false});
  }
}

}  // namespace detail

template <class Visitor>
void traverse(const PointCloud& pc, Ray ray, Visitor& visitor, const TraversalOptions& options,
              TraversalScratch& scratch) {
  auto& heap = scratch.heap;
  heap.clear();
  if (pc.empty()) return;
  const std::vector<OctreeNode>& nodes = pc.nodes();
  float t0, t1;
  if (!nodes[0].bounds.intersect(ray, t0, t1)) return;
  detail::pushEntry(heap, {t0, t0, t1, 0, HitKind::Node, false});
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), std::greater<>{});
    const TraversalEntry e = heap.back();
    heap.pop_back();
    if (e.key > ray.tmax) break;
    switch (e.kind) {
      case HitKind::Node: {
        ++scratch.stats.nodesPopped;
        const OctreeNode& node = nodes[e.id];
        if (!options.surfels && node.lvoxelEnd == node.lvoxelBegin) break;
        if (detail::useCluster(node, ray, options)) {
          detail::pushClusters(pc, e.id, e.key, ray, options.surfels, heap);
        } else if (node.isLeaf()) {
          detail::pushLeafElements(pc, node, ray, options.surfels, scratch);
        } else {
          for (uint32_t c = node.childBegin; c < node.childBegin + node.childCount; ++c)
            if (nodes[c].bounds.intersect(ray, t0, t1))
              detail::pushEntry(heap, {t0, t0, t1, c, HitKind::Node, false});
        }
        break;
      }
      case HitKind::Surfel:
        ++scratch.stats.elementsVisited;
        visitor.surfel(e.id, e.t0, e.front);
        return;
      case HitKind::SurfelCluster:
        ++scratch.stats.elementsVisited;
        if (!visitor.surfelCluster(e.id, e.t0, e.front, e.t1)) return;
        break;
      case HitKind::Lvoxel:
        ++scratch.stats.elementsVisited;
        // An opaque hit found later may end the chord early.
        if (!visitor.lvoxel(e.id, e.t0, std::min(e.t1, ray.tmax))) return;
        break;
      case HitKind::LvoxelCluster:
        ++scratch.stats.elementsVisited;
        if (!visitor.lvoxelCluster(e.id, e.t0, std::min(e.t1, ray.tmax))) return;
        break;
    }
  }
}

}  // namespace lvox
