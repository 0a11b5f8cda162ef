#pragma once
// The traversal as it was before the fast paths (pointcloud/traversal.h at c0757fa),
// kept verbatim as the reference the optimised traversal must reproduce exactly: every
// visit, in the same order, with bit-identical arguments (ties included, which the heap
// breaks its own way).
#include <algorithm>
#include <functional>
#include <vector>

#include "pointcloud/traversal.h"

namespace lvox::reference {

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
    const uint32_t k = pc.lvoxelClusterOf(n);
    const LvoxelCluster& c = pc.lvoxelClusters()[k];
    float t0, t1;
    if (intersectBox(ray, c.box.lo, c.box.hi, t0, t1))
      pushEntry(heap, {std::max(t0, entry), t0, t1, k, HitKind::LvoxelCluster, false});
  }
  if (surfels && node.surfelEnd > node.surfelBegin) {
    const SurfelCluster& c = pc.surfelClusters()[n];
    float t0, t1;
    if (c.cover.intersect(ray, t0, t1)) {
      const float coverage = c.coverage(ray.dir);
      if (coverage > 0.0f)
        pushEntry(heap, {std::max(t0, entry), t0, coverage, n, HitKind::SurfelCluster, false});
    }
  }
}

inline void pushLeafElements(const PointCloud& pc, const OctreeNode& node, Ray& ray, bool surfels,
                             TraversalScratch& s) {
  const CloudSurfels& sf = pc.surfels();
  for (uint32_t i = node.surfelBegin; surfels && i < node.surfelEnd; ++i) {
    ++s.stats.elementsTested;
    float t;
    bool front;
    if (intersectDisk(ray, sf.position(i), sf.normal(i), sf.radius(i), pc.diskClip(i), t, front) &&
        !(sf.enclosedSides(i) & (front ? 1u : 2u))) {
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
        if (!visitor.surfelCluster(e.id, e.t0, e.t1)) return;
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

}  // namespace lvox::reference
