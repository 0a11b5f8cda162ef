// The optimised traversal (nearest-disk search, SIMD child tests, packed elements) must
// visit exactly what the original heap traversal visits: the same elements in the same
// order with bit-identical arguments, including where the heap's order decides exact
// ties (coplanar disks on axis-aligned lattices hit at the same t).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdio>
#include <vector>

#include "pointcloud/lvoxel_sampler.h"
#include "pointcloud/scenes.h"
#include "pointcloud/surfel_sampler.h"
#include "src/core/rng.h"
#include "src/core/sampling.h"
#include "traversal_reference.h"

namespace lvox {
namespace {

struct Call {
  HitKind kind;
  uint32_t id;
  uint32_t a, b;  // float bits: t (t0) and t1 or coverage
  bool front;
  bool operator==(const Call&) const = default;
};

// Records every call; stops (returns false) at the `stopAt`-th non-surfel visit, so that
// early exits are compared too.
struct CallLog {
  std::vector<Call> calls;
  int stopAt = -1;
  bool record(HitKind k, uint32_t id, float a, float b, bool front) {
    calls.push_back({k, id, std::bit_cast<uint32_t>(a), std::bit_cast<uint32_t>(b), front});
    return static_cast<int>(calls.size()) != stopAt;
  }
  void surfel(uint32_t i, float t, bool front) { record(HitKind::Surfel, i, t, t, front); }
  bool surfelCluster(uint32_t n, float t, float c) {
    return record(HitKind::SurfelCluster, n, t, c, false);
  }
  bool lvoxel(uint32_t i, float t0, float t1) { return record(HitKind::Lvoxel, i, t0, t1, false); }
  bool lvoxelCluster(uint32_t n, float t0, float t1) {
    return record(HitKind::LvoxelCluster, n, t0, t1, false);
  }
};

// Coincident cubes (media overlapping in one cell) are entered at the same distance: the
// lattice march visits them in index order, the heap in its own order among equal keys.
// Runs of such visits are put in index order; the last run, when the visitor stopped the
// ray, keeps only its distances (which of the cell's cubes came before the stop is the
// order's to say).
void orderCoincidentCubes(std::vector<Call>& calls, bool stopped) {
  auto same = [](const Call& x, const Call& y) {
    return x.kind == HitKind::Lvoxel && y.kind == HitKind::Lvoxel && x.a == y.a && x.b == y.b;
  };
  for (size_t begin = 0; begin < calls.size();) {
    size_t end = begin + 1;
    while (end < calls.size() && same(calls[begin], calls[end])) ++end;
    std::sort(calls.begin() + static_cast<std::ptrdiff_t>(begin),
              calls.begin() + static_cast<std::ptrdiff_t>(end),
              [](const Call& x, const Call& y) { return x.id < y.id; });
    if (stopped && end == calls.size() && calls[begin].kind == HitKind::Lvoxel)
      for (size_t i = begin; i < end; ++i) calls[i].id = 0;
    begin = end;
  }
}

struct Counts {
  size_t rays = 0, nearestDisk = 0, heap = 0, lattice = 0, surfelHits = 0, lvoxelVisits = 0;
  size_t latticeClusterVisits = 0;  // lvoxel clusters visited on rays that marched first
};

// Traces `ray` both ways and compares; returns false (with a message) on a difference.
::testing::AssertionResult sameVisits(const PointCloud& pc, const Ray& ray,
                                      const TraversalOptions& o, int stopAt, TraversalScratch& fast,
                                      TraversalScratch& ref, Counts& n) {
  CallLog a, b;
  a.stopAt = b.stopAt = stopAt;
  const TraversalStats before = fast.stats;
  traverse(pc, ray, a, o, fast);
  reference::traverse(pc, ray, b, o, ref);
  ++n.rays;
  n.nearestDisk += fast.stats.nearestDiskRays - before.nearestDiskRays;
  n.heap += fast.stats.heapRays - before.heapRays;
  n.lattice += fast.stats.latticeRays - before.latticeRays;
  if (!o.surfels && pc.lvoxelLattice()) {
    const bool stopped = stopAt > 0 && static_cast<int>(b.calls.size()) == stopAt;
    orderCoincidentCubes(a.calls, stopped);
    orderCoincidentCubes(b.calls, stopped);
  }
  for (const Call& c : b.calls) {
    n.latticeClusterVisits += c.kind == HitKind::LvoxelCluster && !o.surfels && pc.lvoxelLattice();
    n.surfelHits += c.kind == HitKind::Surfel;
    n.lvoxelVisits += c.kind == HitKind::Lvoxel || c.kind == HitKind::LvoxelCluster;
  }
  if (a.calls == b.calls) return ::testing::AssertionSuccess();
  auto r = ::testing::AssertionFailure();
  r << "options {" << o.maxSolidAngle << ", " << o.maxLvoxelSolidAngle << ", " << o.surfels
    << "} ray o=" << ray.origin << " d=" << ray.dir << " tmin=" << ray.tmin << " tmax=" << ray.tmax
    << ": " << a.calls.size() << " visits vs " << b.calls.size() << " in the reference";
  for (size_t i = 0; i < std::max(a.calls.size(), b.calls.size()); ++i) {
    const bool same = i < a.calls.size() && i < b.calls.size() && a.calls[i] == b.calls[i];
    if (same) continue;
    r << "; first difference at visit " << i;
    if (i < a.calls.size())
      r << " got kind " << int(a.calls[i].kind) << " id " << a.calls[i].id << " t "
        << std::bit_cast<float>(a.calls[i].a);
    if (i < b.calls.size())
      r << " want kind " << int(b.calls[i].kind) << " id " << b.calls[i].id << " t "
        << std::bit_cast<float>(b.calls[i].a);
    break;
  }
  return r;
}

// Random disks and cubes of varying size in [0,1]^3, some coincident, some axis-aligned.
// `onLattice`: the cubes are cells of one lattice (lvoxel-only rays march through it),
// some cells holding two or three (overlapping media); else half of them overlap.
PointCloud randomCloud(uint64_t seed, size_t surfels, size_t lvoxels, bool onLattice = false) {
  Rng rng(seed, 0);
  auto point = [&] { return Vec3(rng.uniform(), rng.uniform(), rng.uniform()); };
  SurfelSet s;
  s.resize(surfels);
  for (size_t i = 0; i < surfels; ++i) {
    s.position[i] = i < 20 ? Vec3(0.5f, 0.5f, 0.5f) : point();
    s.normal[i] = i % 3 == 0 ? Vec3(0, 0, 1) : uniformSphere(rng.uniform(), rng.uniform());
    if (i % 7 == 0) s.position[i].z = 0.25f;  // a plane of coplanar disks: exact ties
    s.radius[i] = 0.005f + 0.03f * rng.uniform();
    s.enclosedSides[i] = static_cast<uint8_t>(i % 11 == 0 ? 1 : 0);
    if (i % 5 == 0) s.clip[i] = {normalize(Vec3(1, 1, 0)), 0.3f * s.radius[i]};
  }
  LvoxelSet l;
  l.resize(lvoxels);
  for (size_t i = 0; i < lvoxels; ++i) {
    // On a grid of spacing 0.04 (faces shared exactly), in a slab of the cube.
    const auto g = [&] { return (std::floor(rng.uniform() * 25.0f) + 0.5f) * 0.04f; };
    const float z =
        onLattice ? 0.5f + (std::floor(rng.uniform() * 12.0f) + 0.5f) * 0.04f : 0.5f + 0.5f * g();
    const float y = g();
    l.position[i] = Vec3(g(), y, z);
    l.halfSize[i] = 0.02f;
    l.sigmaA[i] = RGB(0.1f);
    l.sigmaS[i] = RGB(rng.uniform());
  }
  return PointCloud(std::move(s), std::move(l));
}

Ray randomRay(Rng& rng) {
  const Vec3 o(rng.uniform() * 1.4f - 0.2f, rng.uniform() * 1.4f - 0.2f, -0.3f);
  Vec3 target(rng.uniform(), rng.uniform(), 1.0f);
  Vec3 d = normalize(target - o);
  const float u = rng.uniform();
  if (u < 0.1f) d = Vec3(0, 0, 1);  // axis-aligned: slabs the ray lies in give NaN
  if (u > 0.9f) d = normalize(Vec3(d.x, -0.0f, d.z));
  return Ray{o, d, 0.0f, rng.uniform() < 0.2f ? 0.3f + rng.uniform() : kInf};
}

const TraversalOptions kOptions[] = {
    {},                    // exact: the nearest-disk search
    {0.0f, 0.05f, true},   // lvoxel clusters (the renderer's default)
    {0.03f, 0.0f, true},   // surfel clusters: the heap only
    {0.0f, 0.05f, false},  // lvoxels only (ray-traced visibility)
    {0.0f, 0.0f, false},
};

TEST(TraversalExact, RandomCloudMatchesTheHeapTraversal) {
  for (uint64_t seed : {1u, 2u, 3u}) {
    const PointCloud pc = randomCloud(seed, 4000, seed == 1 ? 0 : 3000, seed == 3);
    ASSERT_EQ(pc.lvoxelLattice() != nullptr, seed == 3);
    Rng rng(seed, 7);
    TraversalScratch fast, ref;
    Counts n;
    for (int r = 0; r < 600; ++r) {
      const Ray ray = randomRay(rng);
      const int stopAt = r % 4 == 0 ? 1 + r % 5 : -1;
      for (const TraversalOptions& o : kOptions)
        ASSERT_TRUE(sameVisits(pc, ray, o, stopAt, fast, ref, n)) << "seed " << seed;
    }
    std::printf(
        "seed %llu: %zu rays, %zu by the nearest-disk search, %zu by the heap, %zu marched, %zu "
        "surfel hits, %zu lvoxel visits\n",
        static_cast<unsigned long long>(seed), n.rays, n.nearestDisk, n.heap, n.lattice,
        n.surfelHits, n.lvoxelVisits);
    EXPECT_GT(n.nearestDisk, n.rays / 10);
    EXPECT_GT(n.surfelHits, n.rays / 10);
    if (seed >= 2) {
      EXPECT_GT(n.lvoxelVisits, n.rays);
    }
    if (seed == 3) {
      EXPECT_GT(n.lattice, n.rays / 3);  // the two lvoxel-only options of kOptions' five
      EXPECT_GT(n.latticeClusterVisits, n.rays / 10);  // the heap took over from the march
    }
  }
}

// Gather rays from the surfels of an axis-aligned room with a fog block: coplanar lattice
// disks tie exactly at every hit (the case where the heap's order decides), as in the
// renderer's interreflection gathers.
TEST(TraversalExact, LatticeGathersMatchTheHeapTraversal) {
  TriangleMesh mesh;
  test::addBox(mesh, Vec3(0, 0, 0), Vec3(2, 1, 1.5f), 0);
  test::addBox(mesh, Vec3(0.5f, 0, 0.4f), Vec3(0.8f, 0.6f, 0.7f), 0);
  test::addSphere(mesh, Vec3(1.4f, 0.3f, 0.8f), 0.2f, 12, 16, 0);
  const float spacing = 0.04f;
  SurfelSet s = sampleSurfelsUniform(mesh, {Material{}}, {spacing, 1.15f, 3});
  const test::BoxMedium fog(Vec3(1.1f, 0.1f, 0.2f), Vec3(1.7f, 0.7f, 0.6f), RGB(0.5f), RGB(1.0f));
  for (const bool withFog : {false, true}) {
    const PointCloud pc(s, withFog ? sampleLvoxels(fog, {0.05f}) : LvoxelSet{});
    const CloudSurfels& cs = pc.surfels();
    Rng rng(5, withFog);
    TraversalScratch fast, ref;
    Counts n;
    for (size_t k = 0; k < 3000; ++k) {
      const size_t i = k * 7919 % cs.size();
      const Vec3 normal = rng.uniform() < 0.5f ? cs.normal(i) : -cs.normal(i);
      const Vec3 d = Frame(normal).toWorld(cosineHemisphere(rng.uniform(), rng.uniform()));
      const Ray ray{cs.position(i), d, 0.25f * spacing, kInf};
      for (const TraversalOptions& o : kOptions)
        ASSERT_TRUE(sameVisits(pc, ray, o, -1, fast, ref, n)) << "fog " << withFog;
    }
    std::printf(
        "fog %d: %zu rays, %zu by the nearest-disk search, %zu by the heap, %zu marched, %zu "
        "surfel hits, %zu lvoxel visits\n",
        withFog, n.rays, n.nearestDisk, n.heap, n.lattice, n.surfelHits, n.lvoxelVisits);
    EXPECT_GT(n.nearestDisk, n.rays / 5);
    EXPECT_GT(n.surfelHits, n.rays / 5);  // half the rays leave the room from its outside
    if (withFog) {
      EXPECT_GT(n.lvoxelVisits, n.rays / 10);
      EXPECT_GT(n.lattice, n.rays / 3);
      EXPECT_GT(n.latticeClusterVisits, 0u);
    }
  }
}

TEST(TraversalExact, AggregateUpdatesKeepTheLayoutsBounds) {
  // updateAggregates grows node bounds to hold the cluster proxies; the layout copies
  // them once, so later updates (the light caches call it) must leave them as they are.
  PointCloud pc = randomCloud(3, 2000, 2000);
  ASSERT_TRUE(pc.traversalLayoutMatchesNodes());
  LvoxelLight& light = pc.mutableLvoxels().light;
  for (uint32_t s = 0; s < light.occupiedCount(); ++s) light.directInScatter(s)[0] = RGB(2.0f);
  std::fill(pc.mutableSurfels().radianceFront.begin(), pc.mutableSurfels().radianceFront.end(),
            RGB(3.0f));
  pc.updateAggregates();
  pc.updateAggregates();
  EXPECT_TRUE(pc.traversalLayoutMatchesNodes());
}

}  // namespace
}  // namespace lvox
