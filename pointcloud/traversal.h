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
// Speed (docs/pointcloud.md, "Traversal speed"). Most gather rays only want the first
// disk. For them `traverse` first runs a depth-first search with a small stack (children
// nearest first, SIMD slab tests on blocks of up to 16 descendants, WideChildren) that
// finds the disk the heap would visit, and falls back to the heap only when the heap's
// own order could matter: lvoxels in front, or two disks in different leaves tied exactly
// (see nearestDisk below). Both paths compute every key and hit distance with the same
// float operations as the original one-box, one-disk tests, so the visits are
// bit-identical to the original heap traversal's (tests/pointcloud/
// test_traversal_exact.cpp keeps that traversal and compares on random and lattice rays).
// Rays that want the lvoxels only march through the lvoxels' lattice instead
// (traverseLvoxelLattice below), handing over to the heap where clusters could start.
//
// Visitor interface (no virtual calls):
//   void surfel(uint32_t i, float t, bool front);       // opaque, ends traversal
//   bool lvoxel(uint32_t i, float t0, float t1);        // false stops
//   bool surfelCluster(uint32_t node, float t, float coverage);  // partial
//   bool lvoxelCluster(uint32_t cluster, float t0, float t1);  // false stops
//                          (cluster: the index in PointCloud::lvoxelClusters())
#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "pointcloud/point_cloud.h"
#include "pointcloud/ray_element.h"
#include "src/core/check.h"

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
  uint64_t nearestDiskRays = 0;  // rays answered by the depth-first nearest-disk search
  uint64_t heapRays = 0;         // rays traversed by the heap (after the search or instead)
  uint64_t latticeRays = 0;      // lvoxel-only rays marched through the lvoxel lattice
  uint64_t cellsMarched = 0;     // the lattice cells with cubes they visited
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

// The traversal's min-heap: libstdc++'s binary heap (std::push_heap / std::pop_heap with
// std::greater, as the traversal first used) step for step, so that entries with equal
// keys still come out in the same order, which decides ties between disks. It moves
// 8-byte (key, slot) items instead of whole entries (the rest of an entry waits in a
// side array until it is popped) and picks the smaller child without a branch.
class TraversalHeap {
 public:
  void clear() {
    items_.clear();
    entries_.clear();
  }
  bool empty() const { return items_.empty(); }
  void push(const TraversalEntry& e) {
    items_.push_back({e.key, static_cast<uint32_t>(entries_.size())});
    entries_.push_back(e);
    siftUp(static_cast<std::ptrdiff_t>(items_.size()) - 1, 0, items_.back());
  }
  TraversalEntry pop() {
    const auto len = static_cast<std::ptrdiff_t>(items_.size()) - 1;
    const Item top = items_[0];
    if (len > 0) {
      const Item last = items_[static_cast<size_t>(len)];
      adjust(len, last);  // __pop_heap: the last item refills the hole left at the top
    }
    items_.pop_back();
    return entries_[top.slot];
  }

 private:
  struct Item {
    float key;
    uint32_t slot;
  };
  // std::__push_heap: moves the hole up while the parent's key is greater.
  void siftUp(std::ptrdiff_t hole, std::ptrdiff_t top, Item value) {
    Item* h = items_.data();
    std::ptrdiff_t parent = (hole - 1) / 2;
    while (hole > top && h[parent].key > value.key) {
      h[hole] = h[parent];
      hole = parent;
      parent = (hole - 1) / 2;
    }
    h[hole] = value;
  }
  // std::__adjust_heap from the top over the first `len` items: the hole goes down to a
  // leaf along the smaller children (the left one only if the right one is greater),
  // then `value` is sifted up from there.
  void adjust(std::ptrdiff_t len, Item value) {
    Item* h = items_.data();
    std::ptrdiff_t hole = 0, second = 0;
    while (second < (len - 1) / 2) {
      second = 2 * (second + 1);
      second -= h[second].key > h[second - 1].key;
      h[hole] = h[second];
      hole = second;
    }
    if ((len & 1) == 0 && second == (len - 2) / 2) {
      second = 2 * (second + 1);
      h[hole] = h[second - 1];
      hole = second - 1;
    }
    siftUp(hole, 0, value);
  }
  std::vector<Item> items_;
  std::vector<TraversalEntry> entries_;
};

// Reusable heap storage: one per thread (or per gather), never shared between threads.
struct TraversalScratch {
  TraversalHeap queue;
  std::vector<TraversalEntry> heap;  // the reference traversal's (tests)
  TraversalStats stats;
};

namespace detail {

// The ray as the child tests use it: origin, 1 / direction and tmin, 4 lanes each.
struct SlabRay {
#if defined(__SSE2__)
  __m128 origin[3], inv[3], tmin;
  explicit SlabRay(const Ray& r) {
    for (int a = 0; a < 3; ++a) {
      origin[a] = _mm_set1_ps(r.origin[a]);
      inv[a] = _mm_set1_ps(1.0f / r.dir[a]);
    }
    tmin = _mm_set1_ps(r.tmin);
  }
#else
  float origin[3], inv[3], tmin;
  explicit SlabRay(const Ray& r) : tmin(r.tmin) {
    for (int a = 0; a < 3; ++a) {
      origin[a] = r.origin[a];
      inv[a] = 1.0f / r.dir[a];
    }
  }
#endif
};

// Bit c set: the ray enters child c's bounds within [tmin, tmax]; entry[c] is then its
// entry distance. Lane by lane this is Bounds3::intersect with the same roundings and
// the same NaN handling (a slab the ray lies in gives NaN and is ignored), so the keys
// are bit-identical: std::max(a, b) is _mm_max_ps(b, a), std::min(a, b) is
// _mm_min_ps(b, a), and the swap is a min and a max; the early exit only saves work.
#if defined(__SSE2__) && defined(__GNUC__) && !defined(__AVX__)
#define LVOX_AVX_DISPATCH 1
// The same test 8 lanes at a time where the CPU has AVX (the build targets plain x86-64,
// so it is compiled for AVX here and chosen at run time): Embree does the same.
template <int W>
__attribute__((target("avx"), noinline)) uint32_t intersectChildrenAvx(const ChildBlock<W>& b,
                                                                       const SlabRay& r, float tmax,
                                                                       float* entry) {
  __m256 origin[3], inv[3];
  for (int a = 0; a < 3; ++a) {
    origin[a] = _mm256_set_m128(r.origin[a], r.origin[a]);
    inv[a] = _mm256_set_m128(r.inv[a], r.inv[a]);
  }
  const __m256 near = _mm256_set_m128(r.tmin, r.tmin), far = _mm256_set1_ps(tmax);
  uint32_t mask = 0;
  for (int h = 0; h < W && b.ref[h] != 0; h += 8) {
    const __m256 unused = _mm256_castsi256_ps(_mm256_set_m128i(
        _mm_cmpeq_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(&b.ref[h + 4])),
                        _mm_setzero_si128()),
        _mm_cmpeq_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(&b.ref[h])),
                        _mm_setzero_si128())));
    __m256 t0 = near, t1 = far;
    for (int a = 0; a < 3; ++a) {
      const __m256 tn =
          _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(&b.lo[a][h]), origin[a]), inv[a]);
      const __m256 tf =
          _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(&b.hi[a][h]), origin[a]), inv[a]);
      t0 = _mm256_max_ps(_mm256_min_ps(tf, tn), t0);
      t1 = _mm256_min_ps(_mm256_max_ps(tn, tf), t1);
    }
    _mm256_store_ps(entry + h, t0);
    const __m256 hit = _mm256_andnot_ps(unused, _mm256_cmp_ps(t0, t1, _CMP_LE_OQ));
    mask |= static_cast<uint32_t>(_mm256_movemask_ps(hit)) << h;
  }
  return mask;
}

inline bool cpuHasAvx() {
  static const bool avx = __builtin_cpu_supports("avx");
  return avx;
}
#endif

// `entry` must be 32-byte aligned.
template <int W>
uint32_t intersectChildren(const ChildBlock<W>& b, const SlabRay& r, float tmax, float* entry) {
#if defined(LVOX_AVX_DISPATCH)
  if (cpuHasAvx()) return intersectChildrenAvx(b, r, tmax, entry);
#endif
#if defined(__SSE2__)
  const __m128 far = _mm_set1_ps(tmax);
  uint32_t mask = 0;
  // Lanes are used from 0 up: a quad that starts unused ends the block.
  for (int h = 0; h < W && b.ref[h] != 0; h += 4) {
    const __m128i unused = _mm_cmpeq_epi32(
        _mm_load_si128(reinterpret_cast<const __m128i*>(&b.ref[h])), _mm_setzero_si128());
    __m128 t0 = r.tmin, t1 = far;
    for (int a = 0; a < 3; ++a) {
      const __m128 tn = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(&b.lo[a][h]), r.origin[a]), r.inv[a]);
      const __m128 tf = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(&b.hi[a][h]), r.origin[a]), r.inv[a]);
      t0 = _mm_max_ps(_mm_min_ps(tf, tn), t0);
      t1 = _mm_min_ps(_mm_max_ps(tn, tf), t1);
    }
    _mm_store_ps(entry + h, t0);
    const __m128 hit = _mm_andnot_ps(_mm_castsi128_ps(unused), _mm_cmple_ps(t0, t1));
    mask |= static_cast<uint32_t>(_mm_movemask_ps(hit)) << h;
  }
  return mask;
#else
  uint32_t mask = 0;
  for (uint32_t c = 0; c < W && b.ref[c] != 0; ++c) {
    float t0 = r.tmin, t1 = tmax;
    for (int a = 0; a < 3; ++a) {
      float tn = (b.lo[a][c] - r.origin[a]) * r.inv[a];
      float tf = (b.hi[a][c] - r.origin[a]) * r.inv[a];
      if (tn > tf) std::swap(tn, tf);
      t0 = std::max(t0, tn);
      t1 = std::min(t1, tf);
    }
    entry[c] = t0;
    if (!(t0 > t1)) mask |= 1u << c;
  }
  return mask;
#endif
}

#if defined(__SSE2__)
// The ray for disk tests, 4 lanes per value.
struct DiskRay {
  __m128 origin[3], dir[3], tmin, tmax;
  explicit DiskRay(const Ray& r) {
    for (int a = 0; a < 3; ++a) {
      origin[a] = _mm_set1_ps(r.origin[a]);
      dir[a] = _mm_set1_ps(r.dir[a]);
    }
    tmin = _mm_set1_ps(r.tmin);
    tmax = _mm_set1_ps(r.tmax);
  }
};

// Four disk tests: per lane t, the hit point relative to the centre (for the cut test),
// and bit masks of the hits (before the cut) and of the front sides.
struct DiskHits4 {
  alignas(16) float t[4];
  alignas(16) float q[3][4];
  uint32_t hits, front;
  // intersectDisk's cut test on lane `lane`: dot(q, n) > offset, in the same order.
  bool cutAway(int lane, const DiskClip& c) const {
    return q[0][lane] * c.normal.x + q[1][lane] * c.normal.y + q[2][lane] * c.normal.z > c.offset;
  }
};

// intersectDisk for the 4 disks at d (records past a leaf's end are masked by the caller;
// the array is padded), lane by lane with the same operations in the same order, so t and
// the verdicts are bit-identical: dot(a, b) is (ax bx + ay by) + az bz, at(t) - c is
// (o + dir t) - c. The cut is left to the caller (DiskHits4::cutAway), for the few disks
// that have one and could matter.
inline void intersectDisks4(const DiskElement* d, const DiskRay& r, DiskHits4& out) {
  __m128 px = _mm_loadu_ps(&d[0].position.x), py = _mm_loadu_ps(&d[1].position.x);
  __m128 pz = _mm_loadu_ps(&d[2].position.x), radius = _mm_loadu_ps(&d[3].position.x);
  _MM_TRANSPOSE4_PS(px, py, pz, radius);
  __m128 nx = _mm_loadu_ps(&d[0].normal.x), ny = _mm_loadu_ps(&d[1].normal.x);
  __m128 nz = _mm_loadu_ps(&d[2].normal.x), unusedFlags = _mm_loadu_ps(&d[3].normal.x);
  _MM_TRANSPOSE4_PS(nx, ny, nz, unusedFlags);
  const __m128 denom = _mm_add_ps(_mm_add_ps(_mm_mul_ps(nx, r.dir[0]), _mm_mul_ps(ny, r.dir[1])),
                                  _mm_mul_ps(nz, r.dir[2]));
  const __m128 cx = _mm_sub_ps(px, r.origin[0]), cy = _mm_sub_ps(py, r.origin[1]);
  const __m128 cz = _mm_sub_ps(pz, r.origin[2]);
  const __m128 tv = _mm_div_ps(
      _mm_add_ps(_mm_add_ps(_mm_mul_ps(cx, nx), _mm_mul_ps(cy, ny)), _mm_mul_ps(cz, nz)), denom);
  const __m128 qx = _mm_sub_ps(_mm_add_ps(r.origin[0], _mm_mul_ps(r.dir[0], tv)), px);
  const __m128 qy = _mm_sub_ps(_mm_add_ps(r.origin[1], _mm_mul_ps(r.dir[1], tv)), py);
  const __m128 qz = _mm_sub_ps(_mm_add_ps(r.origin[2], _mm_mul_ps(r.dir[2], tv)), pz);
  const __m128 qq =
      _mm_add_ps(_mm_add_ps(_mm_mul_ps(qx, qx), _mm_mul_ps(qy, qy)), _mm_mul_ps(qz, qz));
  const __m128 absDenom = _mm_andnot_ps(_mm_set1_ps(-0.0f), denom);
  __m128 hit = _mm_cmpnlt_ps(absDenom, _mm_set1_ps(1e-12f));  // !(|denom| < 1e-12)
  hit = _mm_and_ps(hit, _mm_and_ps(_mm_cmpgt_ps(tv, r.tmin), _mm_cmplt_ps(tv, r.tmax)));
  hit = _mm_and_ps(hit, _mm_cmpngt_ps(qq, _mm_mul_ps(radius, radius)));  // !(q.q > r r)
  _mm_store_ps(out.t, tv);
  _mm_store_ps(out.q[0], qx);
  _mm_store_ps(out.q[1], qy);
  _mm_store_ps(out.q[2], qz);
  out.front = static_cast<uint32_t>(_mm_movemask_ps(_mm_cmplt_ps(denom, _mm_setzero_ps())));
  out.hits = static_cast<uint32_t>(_mm_movemask_ps(hit));
}
#endif

// ---- Heap traversal: the reference order ----

inline void pushEntry(TraversalHeap& heap, const TraversalEntry& e) { heap.push(e); }

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
                         bool surfels, TraversalHeap& heap) {
  const OctreeNode& node = pc.nodes()[n];
  if (node.lvoxelEnd > node.lvoxelBegin) {
    const uint32_t k = pc.lvoxelClusterOf(n);
    const LvoxelCluster& c = pc.lvoxelClusters()[k];
    float t0, t1;
    if (intersectBox(ray, c.box.lo, c.box.hi, t0, t1))
      pushEntry(heap, {std::max(t0, entry), t0, t1, k, HitKind::LvoxelCluster, false});
  }
  if (surfels && node.surfelEnd > node.surfelBegin) {
    LVOX_DCHECK(pc.hasSurfelClusters(), "surfel clusters used but not kept (OctreeSettings)");
    const SurfelCluster& c = pc.surfelClusters()[n];
    float t0, t1;
    if (c.cover.intersect(ray, t0, t1)) {
      const float coverage = c.coverage(ray.dir);
      if (coverage > 0.0f)
        pushEntry(heap, {std::max(t0, entry), t0, coverage, n, HitKind::SurfelCluster, false});
    }
  }
}

// Tests a leaf's disks (4 at a time where SSE2 is there) and lvoxels and pushes their
// hits in element order; each disk hit shrinks tmax for the disks after it, exactly as
// the one-by-one loop did (a 4-wide test uses the tmax at its start, and every lane is
// checked against the current tmax before it is pushed).
// `marchedToTmin`: the lvoxels the ray enters before ray.tmin were visited already (by the
// lattice march, which hands over at tmin), so cubes entered at or before it are passed.
inline void pushLeafElements(const PointCloud& pc, const TraversalNode& leaf, Ray& ray,
                             bool surfels, bool marchedToTmin, TraversalScratch& s) {
  const DiskElement* disks = pc.disks().data();
  const uint32_t begin = leaf.ref & OctreeChildren::kIndexMask,
                 end = surfels ? leaf.surfelEnd : begin;
  s.stats.elementsTested += end - begin;
  auto push = [&](uint32_t i, float t, bool front) {
    if (disks[i].flags & (front ? 1u : 2u)) return;
    s.queue.push({t, t, t, i, HitKind::Surfel, front});
    ray.tmax = t;  // opaque: everything behind is hidden
  };
#if defined(__SSE2__)
  for (uint32_t i = begin; i < end; i += 4) {
    const DiskRay r(ray);
    DiskHits4 h;
    intersectDisks4(disks + i, r, h);
    uint32_t hits = h.hits;
    if (end - i < 4) hits &= (1u << (end - i)) - 1u;
    for (; hits; hits &= hits - 1) {
      const auto lane = static_cast<int>(std::countr_zero(hits));
      const uint32_t k = i + static_cast<uint32_t>(lane);
      if (!(h.t[lane] < ray.tmax) ||
          ((disks[k].flags & DiskElement::kClipped) && h.cutAway(lane, pc.diskClip(k))))
        continue;
      push(k, h.t[lane], (h.front >> lane) & 1u);
    }
  }
#else
  for (uint32_t i = begin; i < end; ++i) {
    float t;
    bool front;
    if (intersectDisk(ray, disks[i], pc.diskClip(i), t, front)) push(i, t, front);
  }
#endif
  const CubeElement* cubes = pc.cubes().data();
  const uint32_t lvoxelBegin = leaf.ref & OctreeChildren::kLvoxels ? leaf.first : leaf.lvoxelEnd;
  for (uint32_t i = lvoxelBegin; i < leaf.lvoxelEnd; ++i) {
    ++s.stats.elementsTested;
    float t0, t1;
    // t0 is max(tmin, the cube's entry): equal to tmin when the cube starts before it.
    if (intersectCube(ray, cubes[i].centre, cubes[i].halfSize, t0, t1) &&
        !(marchedToTmin && t0 == ray.tmin))
      pushEntry(s.queue, {t0, t0, t1, i, HitKind::Lvoxel, false});
  }
}

// Opens an inner node: its children the ray enters, pushed in child order (the order
// fixes how the heap breaks ties, so it must not change).
inline void pushChildren(const PointCloud& pc, const TraversalNode& node, const SlabRay& slab,
                         float tmax, TraversalHeap& heap) {
  const OctreeChildren& block = pc.childBlocks()[node.ref & OctreeChildren::kIndexMask];
  alignas(32) float entry[8];
  for (uint32_t hits = intersectChildren(block, slab, tmax, entry); hits; hits &= hits - 1) {
    const auto c = static_cast<uint32_t>(std::countr_zero(hits));
    pushEntry(heap, {entry[c], entry[c], entry[c], node.first + c, HitKind::Node, false});
  }
}

// Whether useCluster can say yes for a node with or without surfels: a cluster needs a
// positive solid angle (useCluster's `maxAngle <= 0` and its comparisons with NaN).
struct ClusterAngles {
  bool surfelNodes, otherNodes;
  explicit ClusterAngles(const TraversalOptions& o)
      : surfelNodes(o.surfels ? o.maxSolidAngle > 0.0f
                              : std::max(o.maxSolidAngle, o.maxLvoxelSolidAngle) > 0.0f),
        otherNodes(std::max(o.maxSolidAngle, o.maxLvoxelSolidAngle) > 0.0f) {}
  bool possible(uint32_t ref) const {
    return ref & OctreeChildren::kSurfels ? surfelNodes : otherNodes;
  }
};

template <class Visitor>
void traverseHeap(const PointCloud& pc, Ray ray, Visitor& visitor, const TraversalOptions& options,
                  TraversalScratch& scratch, bool marchedToTmin = false) {
  ++scratch.stats.heapRays;
  TraversalHeap& heap = scratch.queue;
  heap.clear();
  const std::vector<OctreeNode>& nodes = pc.nodes();
  const TraversalNode* tnodes = pc.traversalNodes().data();
  float t0, t1;
  if (!nodes[0].bounds.intersect(ray, t0, t1)) return;
  const SlabRay slab(ray);
  const ClusterAngles clusters(options);
  pushEntry(heap, {t0, t0, t1, 0, HitKind::Node, false});
  while (!heap.empty()) {
    const TraversalEntry e = heap.pop();
    if (e.key > ray.tmax) break;
    switch (e.kind) {
      case HitKind::Node: {
        ++scratch.stats.nodesPopped;
        const TraversalNode& node = tnodes[e.id];
        if (!options.surfels && !(node.ref & OctreeChildren::kLvoxels)) break;
        if (clusters.possible(node.ref) && useCluster(nodes[e.id], ray, options)) {
          pushClusters(pc, e.id, e.key, ray, options.surfels, heap);
        } else if (node.ref & OctreeChildren::kLeaf) {
          pushLeafElements(pc, node, ray, options.surfels, marchedToTmin, scratch);
        } else {
          pushChildren(pc, node, slab, ray.tmax, heap);
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

// ---- Depth-first nearest-disk search ----
//
// Which disk does the heap visit first? Leaves pop in the order of their keys k (entry
// distances), and a disk hit at t enters the heap when its leaf pops, so it pops at
// f = max(k, t) (a disk may start a rounding before its leaf's box). Working through
// that order, the heap visits the disk that is least in (f, t, k, index): smaller t
// wins among equal f (a later disk at t passes only if t < tmax), smaller k among equal
// t (its leaf pops first), and within a leaf the first disk in index order. The order
// of leaves with EQUAL keys is the heap's own, so the search gives up on a tie the heap
// would break: another disk of equal f in another leaf with the same key, or any other
// disk of equal f when the winner lies before its leaf's key (f = k). Any node with
// lvoxels whose key is not past the winner also sends the ray to the heap, since the
// heap visits lvoxels (or their clusters) in front. Nodes are pruned only when their key
// is past the best f, so every disk of equal f is seen.

struct DiskCandidate {
  float f, t, key;
  uint32_t leaf, index;
  bool front;
  bool before(const DiskCandidate& o) const {
    if (t != o.t) return t < o.t;
    if (key != o.key) return key < o.key;
    return index < o.index;
  }
};

struct NearestDisk {
  static constexpr int kMaxTies = 8;
  explicit NearestDisk(float rayTmax) : limit(rayTmax) {}
  float limit;  // best.f once found, else the ray's tmax: keys past it are pruned
  bool found = false;
  bool tooManyTies = false;
  DiskCandidate best;
  std::array<DiskCandidate, kMaxTies> ties;  // every candidate with f == best.f (not zeroed)
  int tieCount = 0;
  bool lvoxels = false;         // a node with lvoxels was reached ...
  float nearestLvoxels = kInf;  // ... the least key of those

  float bound() const { return limit; }
  void noteLvoxels(float key) {
    lvoxels = true;
    nearestLvoxels = std::min(nearestLvoxels, key);
  }
  // The heap would visit lvoxels (or their clusters) before the disk, or instead of none.
  bool lvoxelsInFront() const { return lvoxels && nearestLvoxels <= bound(); }
  void offer(const DiskCandidate& c) {
    if (!found || c.f < best.f) {
      found = true;
      best = c;
      limit = c.f;
      ties[0] = c;
      tieCount = 1;
      return;
    }
    if (c.f > best.f) return;
    if (tieCount == kMaxTies) {
      tooManyTies = true;
      return;
    }
    ties[tieCount++] = c;
    if (c.before(best)) best = c;
  }
  // True when the heap's tie-breaking cannot change the answer.
  bool unambiguous() const {
    if (tooManyTies) return false;
    for (int i = 0; i < tieCount; ++i) {
      const DiskCandidate& c = ties[i];
      if (c.leaf != best.leaf && (c.key == best.key || best.t < best.key)) return false;
    }
    return true;
  }
};

// The disks [begin, end) of the leaf entered at `key` (the first surfel names the leaf).
inline void testLeafDisks(const PointCloud& pc, uint32_t begin, uint32_t end, float key,
                          const Ray& ray, NearestDisk& nearest, TraversalStats& stats) {
  const DiskElement* disks = pc.disks().data();
  stats.elementsTested += end - begin;
#if defined(__SSE2__)
  const DiskRay r(ray);
  for (uint32_t i = begin; i < end; i += 4) {
    DiskHits4 h;
    intersectDisks4(disks + i, r, h);
    uint32_t hits = h.hits;
    if (end - i < 4) hits &= (1u << (end - i)) - 1u;
    for (; hits; hits &= hits - 1) {
      const auto lane = static_cast<int>(std::countr_zero(hits));
      const uint32_t k = i + static_cast<uint32_t>(lane);
      const bool front = (h.front >> lane) & 1u;
      const float f = std::max(key, h.t[lane]);
      // An enclosed side is passed; the cut (a separate array) is read last.
      if ((disks[k].flags & (front ? 1u : 2u)) || f > nearest.bound() ||
          ((disks[k].flags & DiskElement::kClipped) && h.cutAway(lane, pc.diskClip(k))))
        continue;
      nearest.offer({f, h.t[lane], key, begin, k, front});
    }
  }
#else
  for (uint32_t i = begin; i < end; ++i) {
    float t;
    bool front;
    if (!intersectDisk(ray, disks[i], pc.diskClip(i), t, front) ||
        (disks[i].flags & (front ? 1u : 2u)))
      continue;
    const float f = std::max(key, t);
    if (f <= nearest.bound()) nearest.offer({f, t, key, begin, i, front});
  }
#endif
}

// 16 bytes, copied whole: a 12-byte entry written as three words and read back as one
// 8-byte and one 4-byte word stalled on store forwarding.
struct alignas(16) StackEntry {
  float key;
  uint32_t ref;        // OctreeChildren::ref encoding
  uint32_t surfelEnd;  // leaves
  uint32_t unused;
};

// Each block leaves at most 15 siblings on the stack, and a block descends at least one
// octree level.
inline constexpr size_t kStackSize = WideChildren::kWidth * (kMaxOctreeDepth + 2);

// Starts loading a leaf's disks (up to 8), so that the misses of a block's leaves overlap.
inline void prefetchDisks(const DiskElement* d, uint32_t count) {
#if defined(__SSE2__)
  const char* first = reinterpret_cast<const char*>(d);
  const char* last = reinterpret_cast<const char*>(d + std::min(count, 8u)) - 1;
  for (const char* p = first; p <= last; p += 64) _mm_prefetch(p, _MM_HINT_T0);
  _mm_prefetch(last, _MM_HINT_T0);
#else
  (void)d, (void)count;
#endif
}

// Opens `block`: children holding only lvoxels are noted, leaves are tested at once
// (nearest first, their disk loads started together so that the misses overlap), and
// inner children are pushed nearest on top.
inline void openBlock(const PointCloud& pc, const WideChildren& block, const SlabRay& slab,
                      const Ray& ray, NearestDisk& nearest,
                      std::array<StackEntry, kStackSize>& stack, size_t& size,
                      TraversalStats& stats) {
  alignas(32) float entry[WideChildren::kWidth];
  std::array<StackEntry, WideChildren::kWidth> leaves;
  size_t leafCount = 0;
  const size_t first = size;
  for (uint32_t hits = intersectChildren(block, slab, nearest.bound(), entry); hits;
       hits &= hits - 1) {
    const auto c = static_cast<uint32_t>(std::countr_zero(hits));
    const uint32_t ref = block.ref[c];
    if (!(ref & OctreeChildren::kSurfels)) {
      nearest.noteLvoxels(entry[c]);
      continue;
    }
    const StackEntry e{entry[c], ref, block.surfelEnd[c], 0};
    if (ref & OctreeChildren::kLeaf) {
      prefetchDisks(pc.disks().data() + (ref & OctreeChildren::kIndexMask),
                    block.surfelEnd[c] - (ref & OctreeChildren::kIndexMask));
      size_t j = leafCount++;
      for (; j > 0 && leaves[j - 1].key > e.key; --j) leaves[j] = leaves[j - 1];
      leaves[j] = e;
      continue;
    }
    // Insertion into the run pushed for this node, farthest first.
    size_t j = size++;
    for (; j > first && stack[j - 1].key < e.key; --j) stack[j] = stack[j - 1];
    stack[j] = e;
  }
  for (size_t l = 0; l < leafCount; ++l) {
    const StackEntry& e = leaves[l];
    if (e.key > nearest.bound()) break;
    ++stats.nodesPopped;
    if (e.ref & OctreeChildren::kLvoxels) nearest.noteLvoxels(e.key);
    testLeafDisks(pc, e.ref & OctreeChildren::kIndexMask, e.surfelEnd, e.key, ray, nearest, stats);
  }
}

// Finds the disk the heap would visit first; false when only the heap can tell.
template <class Visitor>
bool nearestDisk(const PointCloud& pc, const Ray& ray, Visitor& visitor, TraversalStats& stats) {
  uint32_t rootEnd;
  const uint32_t root = pc.searchRoot(rootEnd);
  if (!(root & OctreeChildren::kSurfels)) return false;
  float t0, t1;
  if (!pc.nodes()[0].bounds.intersect(ray, t0, t1)) {
    ++stats.nearestDiskRays;  // misses the cloud
    return true;
  }
  const SlabRay slab(ray);
  NearestDisk nearest(ray.tmax);
  if (root & OctreeChildren::kLeaf) {
    if (root & OctreeChildren::kLvoxels) nearest.noteLvoxels(t0);
    testLeafDisks(pc, root & OctreeChildren::kIndexMask, rootEnd, t0, ray, nearest, stats);
  } else {
    std::array<StackEntry, kStackSize> stack;
    size_t size = 0;
    stack[size++] = {t0, root, rootEnd, 0};
    // Lvoxels before any disk: the heap will almost surely be needed, so stop searching
    // (lvoxelsInFront() below then holds; stopping early never changes an answer).
    while (size > 0 && !(nearest.lvoxels && !nearest.found)) {
      const StackEntry e = stack[--size];
      if (e.key > nearest.bound()) continue;
      ++stats.nodesPopped;
      openBlock(pc, pc.wideBlocks()[e.ref & WideChildren::kIndexMask], slab, ray, nearest, stack,
                size, stats);
    }
  }
  if (nearest.lvoxelsInFront() || !nearest.unambiguous()) return false;
  ++stats.nearestDiskRays;
  if (nearest.found) {
    ++stats.elementsVisited;
    visitor.surfel(nearest.best.index, nearest.best.t, nearest.best.front);
  }
  return true;
}

// ---- Lvoxel-only rays: the lattice march ----
//
// A ray that wants the lvoxels only (TraversalOptions::surfels false) visits every lvoxel
// it crosses where no cluster stands for it, and those cubes tile one lattice: a 3D-DDA
// over its cells finds them in order without the heap, which pushed and popped each one.
// Clusters are used only beyond PointCloud::lvoxelClusterFreeReach, so the march covers
// the cubes entered up to that reach and the heap the rest, from the reach on: the visits
// are the heap's, each cube's chord computed by the same intersectCube. What can differ
// is the order among cubes entered at the same distance (the heap's order among equal
// keys; the march takes a cell's cubes in index order) and cubes the ray crosses only
// within a rounding (tests/pointcloud/test_traversal_exact.cpp).
template <class Visitor>
void traverseLvoxelLattice(const PointCloud& pc, const Ray& ray, Visitor& visitor,
                           const TraversalOptions& options, TraversalScratch& scratch) {
  ++scratch.stats.latticeRays;
  const float reach =
      pc.lvoxelClusterFreeReach(std::max(options.maxSolidAngle, options.maxLvoxelSolidAngle));
  const bool marched = reach >= ray.tmin;
  if (marched) {
    const CubeElement* cubes = pc.cubes().data();
    const Vec3 inv = inverseDirection(ray);
    TraversalStats& stats = scratch.stats;
    // Cells entered a little past the reach may hold cubes entered at it (roundings).
    const bool go = pc.lvoxelLattice()->march(ray, reach * 1.0001f, [&](const uint32_t* list) {
      ++stats.cellsMarched;
      for (;; ++list) {
        const uint32_t i = *list & LvoxelLattice::kIndexMask;
        ++stats.elementsTested;
        float t0, t1;
        if (intersectCube(ray, inv, cubes[i].centre, cubes[i].halfSize, t0, t1) && t0 <= reach) {
          ++stats.elementsVisited;
          if (!visitor.lvoxel(i, t0, t1)) return false;
        }
        if (*list & LvoxelLattice::kLastInCell) return true;
      }
    });
    if (!go || !(reach < ray.tmax)) return;
  }
  Ray beyond = ray;
  beyond.tmin = std::max(ray.tmin, reach);
  traverseHeap(pc, beyond, visitor, options, scratch, marched);
}

}  // namespace detail

template <class Visitor>
void traverse(const PointCloud& pc, const Ray& ray, Visitor& visitor,
              const TraversalOptions& options, TraversalScratch& scratch) {
  if (pc.empty()) return;
  // Lvoxels only, and none: the walk would pop the root and meet nothing.
  if (!options.surfels && pc.lvoxels().size() == 0) return;
  if (!options.surfels && pc.lvoxelLattice()) {
    detail::traverseLvoxelLattice(pc, ray, visitor, options, scratch);
    return;
  }
  // Surfel clusters would be visited before the first disk: only the heap handles them.
  if (options.surfels && !(options.maxSolidAngle > 0.0f) &&
      detail::nearestDisk(pc, ray, visitor, scratch.stats))
    return;
  detail::traverseHeap(pc, ray, visitor, options, scratch);
}

}  // namespace lvox
