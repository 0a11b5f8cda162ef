#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <set>

#include "pointcloud/element_bounds.h"
#include "pointcloud/traversal.h"
#include "src/core/rng.h"
#include "src/core/sampling.h"

namespace lvox {
namespace {

// Random disks and cubes of varying size in [0,1]^3, plus a few coincident points.
PointCloud randomCloud(uint64_t seed, size_t surfels, size_t lvoxels,
                       const OctreeSettings& settings = {}) {
  Rng rng(seed, 0);
  auto point = [&] { return Vec3(rng.uniform(), rng.uniform(), rng.uniform()); };
  SurfelSet s;
  s.resize(surfels);
  for (size_t i = 0; i < surfels; ++i) {
    s.position[i] = i < 20 ? Vec3(0.5f, 0.5f, 0.5f) : point();
    s.normal[i] = uniformSphere(rng.uniform(), rng.uniform());
    s.radius[i] = 0.005f + 0.02f * rng.uniform();
    s.albedo[i] = RGB(0.5f);
    s.radianceFront[i] = RGB(rng.uniform());
  }
  LvoxelSet l;
  l.resize(lvoxels);
  for (size_t i = 0; i < lvoxels; ++i) {
    l.position[i] = point();
    l.halfSize[i] = 0.005f + 0.02f * rng.uniform();
    l.sigmaA[i] = RGB(0.1f);
    l.sigmaS[i] = RGB(rng.uniform());
  }
  return PointCloud(std::move(s), std::move(l), settings);
}

Ray randomRay(Rng& rng) {
  const Vec3 o(rng.uniform() * 1.4f - 0.2f, rng.uniform() * 1.4f - 0.2f, -0.3f);
  const Vec3 target(rng.uniform(), rng.uniform(), 1.0f);
  return Ray{o, normalize(target - o), 0.0f, kInf};
}

TEST(Octree, NodesPartitionElementsAndBoundsContainThem) {
  const PointCloud pc = randomCloud(1, 3000, 2000);
  const auto& nodes = pc.nodes();
  ASSERT_FALSE(nodes.empty());
  EXPECT_EQ(nodes[0].surfelEnd - nodes[0].surfelBegin, 3000u);
  EXPECT_EQ(nodes[0].lvoxelEnd - nodes[0].lvoxelBegin, 2000u);
  size_t leafElements = 0;
  for (const OctreeNode& n : nodes) {
    if (n.isLeaf()) {
      leafElements += n.elementCount();
      // 20 coincident surfels cannot be split: they stay in one leaf at the depth cap.
      if (n.elementCount() > OctreeSettings{}.leafSize) {
        EXPECT_EQ(n.surfelEnd - n.surfelBegin, n.elementCount());
      }
      for (uint32_t s = n.surfelBegin; s < n.surfelEnd; ++s) {
        const Bounds3 b = diskBounds(pc.disks()[s]);
        ASSERT_TRUE(n.bounds.contains(b.lo) && n.bounds.contains(b.hi));
      }
      continue;
    }
    uint32_t s = n.surfelBegin, l = n.lvoxelBegin;
    for (uint32_t c = n.childBegin; c < n.childBegin + n.childCount; ++c) {
      ASSERT_EQ(nodes[c].surfelBegin, s);
      ASSERT_EQ(nodes[c].lvoxelBegin, l);
      s = nodes[c].surfelEnd;
      l = nodes[c].lvoxelEnd;
      ASSERT_TRUE(n.bounds.contains(nodes[c].bounds.lo) && n.bounds.contains(nodes[c].bounds.hi));
    }
    ASSERT_EQ(s, n.surfelEnd);
    ASSERT_EQ(l, n.lvoxelEnd);
  }
  EXPECT_EQ(leafElements, 5000u);
  const PointCloudMemory m = pc.memory();
  // A surfel's geometry is held once, in its disk record (three empty ones pad the end);
  // the border cuts are in the traversal layout, only for the disks that are cut.
  EXPECT_EQ(CloudSurfels::bytesPerElement(), 68u);
  EXPECT_EQ(m.surfelBytes, 3003u * sizeof(DiskElement) +
                               3000u * (CloudSurfels::bytesPerElement() - sizeof(DiskElement)));
  EXPECT_EQ(m.lvoxelBytes, 2000u * LvoxelSet::bytesPerElement());
  EXPECT_GE(m.octreeBytes, nodes.size() * pc.bytesPerNode());
}

TEST(Octree, BuildIsDeterministicAcrossThreadCounts) {
  const PointCloud a = randomCloud(2, 20000, 5000);
  tbb::task_arena serial(1);
  PointCloud b;
  serial.execute([&] { b = randomCloud(2, 20000, 5000); });
  ASSERT_EQ(a.nodes().size(), b.nodes().size());
  for (size_t i = 0; i < a.nodes().size(); ++i) {
    ASSERT_EQ(a.nodes()[i].childBegin, b.nodes()[i].childBegin);
    ASSERT_EQ(a.nodes()[i].surfelEnd, b.nodes()[i].surfelEnd);
    for (int k = 0; k < kShCoefficients; ++k)
      ASSERT_EQ(a.surfelClusters()[i].power[k], b.surfelClusters()[i].power[k]);
  }
  for (size_t i = 0; i < a.surfels().size(); ++i)
    ASSERT_EQ(a.surfels().position(i), b.surfels().position(i));
}

struct Visit {
  float t;
  uint32_t id;
  bool surfel;
};

struct Recorder {
  std::vector<Visit> visits;
  void surfel(uint32_t i, float t, bool) { visits.push_back({t, i, true}); }
  bool surfelCluster(uint32_t, float, float) {
    ADD_FAILURE() << "no clusters in exact mode";
    return false;
  }
  bool lvoxel(uint32_t i, float t0, float) {
    visits.push_back({t0, i, false});
    return true;
  }
  bool lvoxelCluster(uint32_t, float, float) { return false; }
};

// Brute force: every lvoxel the ray crosses before the nearest surfel, and that surfel.
std::vector<Visit> bruteForce(const PointCloud& pc, const Ray& ray) {
  std::vector<Visit> out;
  float tSurfel = kInf;
  uint32_t nearest = 0;
  for (uint32_t i = 0; i < pc.surfels().size(); ++i) {
    float t;
    bool front;
    Ray r = ray;
    r.tmax = tSurfel;
    if (intersectDisk(r, pc.surfels().position(i), pc.surfels().normal(i), pc.surfels().radius(i),
                      pc.diskClip(i), t, front)) {
      tSurfel = t;
      nearest = i;
    }
  }
  for (uint32_t i = 0; i < pc.lvoxels().size(); ++i) {
    float t0, t1;
    Ray r = ray;
    r.tmax = tSurfel;
    if (lvoxelBounds(pc.lvoxels(), i).intersect(r, t0, t1) && t1 > t0)
      out.push_back({t0, i, false});
  }
  std::sort(out.begin(), out.end(), [](const Visit& a, const Visit& b) { return a.t < b.t; });
  if (tSurfel < kInf) out.push_back({tSurfel, nearest, true});
  return out;
}

TEST(Traversal, VisitsElementsFrontToBackAndMatchesBruteForce) {
  const PointCloud pc = randomCloud(3, 4000, 3000);
  Rng rng(3, 1);
  TraversalScratch scratch;
  size_t rays = 0, withSurfel = 0, lvoxelVisits = 0;
  for (int r = 0; r < 300; ++r) {
    const Ray ray = randomRay(rng);
    Recorder rec;
    traverse(pc, ray, rec, TraversalOptions{}, scratch);
    for (size_t k = 1; k < rec.visits.size(); ++k)
      ASSERT_LE(rec.visits[k - 1].t, rec.visits[k].t) << "ray " << r << " visit " << k;
    const std::vector<Visit> expected = bruteForce(pc, ray);
    ASSERT_EQ(rec.visits.size(), expected.size()) << "ray " << r;
    std::set<std::pair<bool, uint32_t>> got, want;
    for (const Visit& v : rec.visits) got.insert({v.surfel, v.id});
    for (const Visit& v : expected) want.insert({v.surfel, v.id});
    ASSERT_EQ(got, want) << "ray " << r;
    ++rays;
    if (!rec.visits.empty() && rec.visits.back().surfel) ++withSurfel;
    for (const Visit& v : rec.visits) lvoxelVisits += v.surfel ? 0 : 1;
  }
  // The random rays must exercise both kinds of elements for the test to mean anything.
  EXPECT_GT(withSurfel, rays / 4);
  EXPECT_GT(lvoxelVisits, rays);
}

TEST(Traversal, ExactTraversalDoesNotNeedSurfelClusters) {
  // Without surfel cluster proxies (what pcb builds when cluster_solid_angle is 0) an exact
  // traversal visits the same elements in the same order, and each node costs the
  // proxy and its cell less.
  const PointCloud with = randomCloud(5, 4000, 3000);
  OctreeSettings settings;
  settings.surfelClusters = false;
  const PointCloud without = randomCloud(5, 4000, 3000, settings);
  ASSERT_EQ(with.nodes().size(), without.nodes().size());
  EXPECT_FALSE(without.hasSurfelClusters());
  EXPECT_TRUE(without.surfelClusters().empty());
  EXPECT_EQ(with.memory().octreeBytes - without.memory().octreeBytes,
            with.nodes().size() * (sizeof(SurfelCluster) + sizeof(Bounds3)));
  Rng rng(5, 1);
  TraversalScratch scratch;
  TraversalOptions lvoxelClusters;
  lvoxelClusters.maxLvoxelSolidAngle = 0.3f;  // lvoxel proxies stay available
  // Records lvoxel cluster visits too (ids past the lvoxels').
  struct WithClusters : Recorder {
    bool lvoxelCluster(uint32_t n, float t0, float) {
      visits.push_back({t0, 1'000'000 + n, false});
      return true;
    }
  };
  size_t clusterVisits = 0;
  for (int r = 0; r < 300; ++r) {
    const Ray ray = randomRay(rng);
    for (const TraversalOptions& o : {TraversalOptions{}, lvoxelClusters}) {
      WithClusters a, b;
      traverse(with, ray, a, o, scratch);
      traverse(without, ray, b, o, scratch);
      ASSERT_EQ(a.visits.size(), b.visits.size()) << "ray " << r;
      for (size_t k = 0; k < a.visits.size(); ++k) {
        EXPECT_EQ(a.visits[k].id, b.visits[k].id) << "ray " << r;
        EXPECT_EQ(a.visits[k].t, b.visits[k].t) << "ray " << r;
        clusterVisits += a.visits[k].id >= 1'000'000;
      }
    }
  }
  // Only lvoxel-only nodes may be proxies, few in this mixed cloud: some must be used.
  EXPECT_GT(clusterVisits, 10u);
}

TEST(Traversal, FirstOpaqueSurfelPrunesEverythingBehindIt) {
  // A wall of surfels at z = 0.2 in front of 20000 lvoxels: rays along +z stop at the
  // wall; no lvoxel behind it is visited and only a few elements are even tested.
  SurfelSet s;
  const int n = 40;
  s.resize(n * n);
  for (int i = 0; i < n * n; ++i) {
    s.position[i] =
        Vec3((static_cast<float>(i % n) + 0.5f) / n, (static_cast<float>(i / n) + 0.5f) / n, 0.2f);
    s.normal[i] = Vec3(0, 0, -1);
    s.radius[i] = 0.75f / n;
  }
  LvoxelSet l;
  Rng rng(4, 0);
  l.resize(20000);
  for (size_t i = 0; i < l.size(); ++i) {
    l.position[i] = Vec3(rng.uniform(), rng.uniform(), 0.3f + 0.7f * rng.uniform());
    l.halfSize[i] = 0.01f;
    l.sigmaS[i] = RGB(0.5f);
  }
  const PointCloud pc(std::move(s), std::move(l));
  TraversalScratch scratch;
  for (int r = 0; r < 50; ++r) {
    const Ray ray{Vec3(0.1f + 0.8f * rng.uniform(), 0.1f + 0.8f * rng.uniform(), 0.0f),
                  Vec3(0, 0, 1), 0.0f, kInf};
    Recorder rec;
    scratch.stats = {};
    traverse(pc, ray, rec, TraversalOptions{}, scratch);
    ASSERT_EQ(rec.visits.size(), 1u);
    EXPECT_TRUE(rec.visits[0].surfel);
    EXPECT_NEAR(rec.visits[0].t, 0.2f, 1e-5f);
    EXPECT_LT(scratch.stats.elementsTested, 100u);
  }
}

}  // namespace
}  // namespace lvox
