// Point-cloud benchmarks: surfel sampling, octree build and gather rays per second on a
// synthetic room of ~200k surfels (4 x 3 x 4 box at spacing 0.02, plus a sphere) with a
// 32k-lvoxel fog block. Run: build/tests/bench/lvox_bench --benchmark_filter=PointCloud
#include <benchmark/benchmark.h>

#include "pointcloud/gather.h"
#include "pointcloud/light_cache.h"
#include "pointcloud/lvoxel_sampler.h"
#include "pointcloud/surfel_sampler.h"

namespace lvox {
namespace {

void addQuad(TriangleMesh& m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const auto base = static_cast<uint32_t>(m.positions.size());
  m.positions.insert(m.positions.end(), {a, b, c, d});
  m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  m.triangleMaterial.insert(m.triangleMaterial.end(), {0u, 0u});
}

TriangleMesh roomMesh() {
  TriangleMesh m;
  const Vec3 lo(0, 0, 0), hi(4, 3, 4);
  const Vec3 p[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z},
                     {lo.x, hi.y, lo.z}, {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z},
                     {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  addQuad(m, p[0], p[1], p[2], p[3]);
  addQuad(m, p[4], p[7], p[6], p[5]);
  addQuad(m, p[0], p[4], p[5], p[1]);
  addQuad(m, p[3], p[2], p[6], p[7]);
  addQuad(m, p[0], p[3], p[7], p[4]);
  addQuad(m, p[1], p[5], p[6], p[2]);
  return m;
}

struct FogBlock {
  Bounds3 box;
  std::vector<Bounds3> active;
  FogBlock() {
    box.lo = Vec3(1.0f, 0.5f, 1.0f);
    box.hi = Vec3(2.6f, 2.1f, 2.6f);
    active.push_back(box);
  }
  Bounds3 bounds() const { return box; }
  const std::vector<Bounds3>& activeBoxes() const { return active; }
  void coefficients(const Vec3& p, RGB& a, RGB& s) const {
    a = box.contains(p) ? RGB(0.2f) : RGB(0.0f);
    s = box.contains(p) ? RGB(0.8f) : RGB(0.0f);
  }
};

const std::vector<Material>& materials() {
  static const std::vector<Material> m = {Material{"grey", RGB(0.6f), RGB(0.0f)}};
  return m;
}

const SurfelSet& roomSurfels() {
  static const SurfelSet s = sampleSurfelsUniform(roomMesh(), materials(), {0.02f, 1.15f, 1});
  return s;
}

const LvoxelSet& fogLvoxels() {
  static const LvoxelSet l = sampleLvoxels(FogBlock{}, {0.05f});
  return l;
}

const PointCloud& litCloud() {
  static const PointCloud pc = [] {
    PointCloud c(roomSurfels(), fogLvoxels());
    cacheDirectLight(
        c, [](const SurfelLightQuery& q) { return q.albedo * (0.5f + 0.5f * q.normal.y); },
        [](const LvoxelLightQuery&) { return RGB(0.1f); });
    return c;
  }();
  return pc;
}

void BM_PointCloudSurfelSampling(benchmark::State& state) {
  const TriangleMesh mesh = roomMesh();
  size_t n = 0;
  for (auto _ : state) {
    const SurfelSet s = sampleSurfelsUniform(mesh, materials(), {0.02f, 1.15f, 1});
    n = s.size();
    benchmark::DoNotOptimize(s.position.data());
  }
  state.counters["surfels"] = static_cast<double>(n);
  state.SetItemsProcessed(static_cast<int64_t>(n) * state.iterations());
}
BENCHMARK(BM_PointCloudSurfelSampling)->Unit(benchmark::kMillisecond);

void BM_PointCloudOctreeBuild(benchmark::State& state) {
  const SurfelSet& s = roomSurfels();
  const LvoxelSet& l = fogLvoxels();
  size_t nodes = 0, bytes = 0;
  for (auto _ : state) {
    state.PauseTiming();
    SurfelSet sc = s;
    LvoxelSet lc = l;
    state.ResumeTiming();
    OctreeSettings settings;
    settings.leafSize = static_cast<uint32_t>(state.range(0));
    const PointCloud pc(std::move(sc), std::move(lc), settings);
    nodes = pc.nodes().size();
    bytes = pc.memoryBytes();
  }
  state.counters["surfels"] = static_cast<double>(s.size());
  state.counters["lvoxels"] = static_cast<double>(l.size());
  state.counters["nodes"] = static_cast<double>(nodes);
  state.counters["bytes"] = static_cast<double>(bytes);
  state.SetItemsProcessed(static_cast<int64_t>(s.size() + l.size()) * state.iterations());
}
// arg = leaf size
BENCHMARK(BM_PointCloudOctreeBuild)->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond)->UseRealTime();

// One thread, 128-ray gathers at random floor points; arg = max solid angle * 1000.
void BM_PointCloudGather(benchmark::State& state) {
  const PointCloud& pc = litCloud();
  GatherOptions o;
  o.samples = 128;
  o.maxSolidAngle = static_cast<float>(state.range(0)) * 1e-3f;
  Rng rng(3, 0);
  TraversalScratch scratch;
  RGB sum(0.0f);
  for (auto _ : state) {
    const Vec3 p(0.2f + 3.6f * rng.uniform(), 0.0f, 0.2f + 3.6f * rng.uniform());
    sum += gatherIrradiance(pc, p, Vec3(0, 1, 0), o, rng, scratch);
  }
  benchmark::DoNotOptimize(sum);
  state.counters["rays/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * 128.0,
                                                benchmark::Counter::kIsRate);
  state.counters["work/ray"] =
      static_cast<double>(scratch.stats.nodesPopped + scratch.stats.elementsTested) /
      (static_cast<double>(state.iterations()) * 128.0);
}
BENCHMARK(BM_PointCloudGather)->Arg(0)->Arg(30)->Arg(100)->Unit(benchmark::kMicrosecond);

// One thread, single front-to-back traversals: rays from the room's floor up through the
// fog block (lvoxels attenuate, the ceiling's surfels stop them); arg = max solid angle
// of lvoxel clusters * 1000 (0: every lvoxel exactly).
void BM_PointCloudTraversal(benchmark::State& state) {
  const PointCloud& pc = litCloud();
  GatherOptions o;
  o.maxLvoxelSolidAngle = static_cast<float>(state.range(0)) * 1e-3f;
  Rng rng(5, 0);
  TraversalScratch scratch;
  RGB sum(0.0f);
  for (auto _ : state) {
    Ray ray;
    ray.origin = Vec3(1.1f + 1.4f * rng.uniform(), 0.01f, 1.1f + 1.4f * rng.uniform());
    ray.dir = normalize(Vec3(0.2f * (rng.uniform() - 0.5f), 1.0f, 0.2f * (rng.uniform() - 0.5f)));
    sum += gatherRay(pc, ray, o, scratch);
  }
  benchmark::DoNotOptimize(sum);
  state.counters["rays/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["work/ray"] =
      static_cast<double>(scratch.stats.nodesPopped + scratch.stats.elementsTested) /
      static_cast<double>(state.iterations());
}
BENCHMARK(BM_PointCloudTraversal)->Arg(0)->Arg(30)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace lvox
