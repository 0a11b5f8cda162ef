// Gathers at ray-tracer speed (issue 13, item 4): the octree traversal the gathers use
// against Embree's closest hit, side by side, on the same rays, scene and thread count.
//
// The point cloud is built by the pcb code path (buildPointCloud, interreflection off),
// so surfel count, buried surfels, lvoxels and gather settings are the renderer's. The
// rays are the interreflection's: 4 stratified cosine-weighted rays from the open side of
// surfels spread evenly over the cloud (in octree order, as the operator builds its
// rows), starting at the gathers' ray offset; and, with media, 16 uniform sphere rays
// from lvoxel centres. Workloads:
//   surfel gathers (disks)    traceGatherRay with the cloud's own visibility: lvoxels in
//                             front, the first surfel disk ends the ray
//   surfel gathers (lvoxels)  the octree part of ray-traced visibility: lvoxels only
//                             (TraversalOptions::surfels = false) up to Embree's hit
//   surfel gathers (traced)   the whole gather ray of ray-traced visibility, the default:
//                             Embree's hit, the lvoxels in front of it, the surfel the
//                             triangle lattice gives for it (traceGatherRay; the delta
//                             lights' shadow rays at the hit are light, not traversal, and
//                             left out). Its ratio is the gather's rate against a bare
//                             Embree ray's.
//   surfel gathers (searched) the same with "hit_lattice_step" 0: the exact nearest-surfel
//                             search at every hit instead of the lattice
//   lvoxel gathers (disks)    sphere rays from lvoxel centres with the cloud's own
//                             visibility
//   lvoxel gathers (lvoxels)  the same rays, the octree part of ray-traced visibility:
//                             lvoxels only up to Embree's hit
//   lvoxel gathers (traced)   the same rays as the lvoxel gathers trace them by default
//                             (ray-traced visibility)
// Lvoxels-only rays march through the lvoxel lattice (traversal.h). Each visibility runs
// with its default lvoxel clusters (defaultLvoxelClusterSolidAngle): none for the traced
// rows, 0.03 sr for the disks'.
// Columns: rays/s of each (millions), their ratio, traversal work per ray (nodes popped +
// lattice cells marched + elements tested), the share of rays the exact heap traversal
// took (see traversal.h).
// Last, the lattice and the search alone: their times per hit point of the surfel gathers'
// rays, and how often the lattice gives the search's surfel.
// Embree traces each workload's rays with RayTracer::intersect (rtcIntersect1). Times are
// the best of --reps runs, octree and Embree interleaved so that load from other
// processes hits both alike; one thread is timed by its CPU clock, more threads by the
// wall clock. The checksum hashes every element each ray reached with the
// bits of its weight: equal checksums mean equal gathers (and equal images).
//
//   build/tests/bench/lvox_gather_speed [--rays N] [--reps R] [--threads 1,2]
//                                       [--surfels N] [SCENE.json ...]
#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "pointcloud/gather.h"
#include "pointcloud/surfel_lookup.h"
#include "pointcloud/triangle_surfel_lattice.h"
#include "src/render/light_set.h"
#include "src/render/pcb_integrator.h"
#include "src/render/render_context.h"
#include "src/render/volume_transport.h"
#include "src/scene/scene_loader.h"
#include "volume/media/media_set.h"

namespace lvox {
namespace {

struct Args {
  size_t rays = 1u << 18;
  int reps = 3;
  std::vector<int> threads;
  int surfels = 0;  // 0: the scene's own target
  std::vector<std::string> scenes;
};

uint64_t mixHash(uint64_t h, uint64_t v) {
  h ^= v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
  return h * 0xbf58476d1ce4e5b9ull;
}

// Every element a gather ray reaches, with its weight's bits.
struct HashSink {
  uint64_t hash = 0;
  void add(uint64_t kind, uint32_t id, const RGB& w) {
    hash = mixHash(hash, kind << 32 | id);
    hash =
        mixHash(hash, uint64_t(std::bit_cast<uint32_t>(w.x)) << 32 | std::bit_cast<uint32_t>(w.y));
    hash = mixHash(hash, std::bit_cast<uint32_t>(w.z));
  }
  void surfel(uint32_t i, bool front, const RGB& w) { add(front ? 1 : 2, i, w); }
  void surfelCluster(uint32_t n, const RGB& w) { add(3, n, w); }
  void lvoxel(uint32_t i, const RGB& w) { add(5, i, w); }
  void lvoxelCluster(uint32_t n, const RGB& w) { add(6, n, w); }
  void beginRay(const Vec3&) {}
  void addBackground(const RGB& w) { add(7, 0, w); }
  void surfaceLight(const RGB& weighted) { add(8, 0, weighted); }
};

enum class Kind { Disks, LvoxelsOnly, Traced, Searched };

struct Workload {
  const char* name;
  Kind kind;
  std::vector<Ray> rays;
};

struct Timing {
  double seconds = 1e30;
  uint64_t checksum = 0;
  double workPerRay = 0.0;
  double heapShare = 0.0;  // rays the heap traversed, of all rays
};

// 4 stratified cosine-weighted rays (2 x 2 strata, as gatherIrradianceInto with 4
// samples) from the open side of evenly spread surfels.
std::vector<Ray> surfelGatherRays(const CloudSurfels& s, size_t count, float offset) {
  std::vector<Ray> rays;
  if (s.size() == 0) return rays;
  const size_t gathers = std::max<size_t>(1, count / 4);
  for (size_t g = 0; g < gathers && rays.size() < count; ++g) {
    const size_t i = g * s.size() / gathers;
    if (s.enclosedSides(i) == 3) continue;
    const Vec3 n = (s.enclosedSides(i) & 1u) ? -s.normal(i) : s.normal(i);
    const Frame frame(n);
    Rng rng(11, i);
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 2; ++c) {
        const float u1 = (static_cast<float>(r) + rng.uniform()) * 0.5f;
        const float u2 = (static_cast<float>(c) + rng.uniform()) * 0.5f;
        rays.push_back(Ray{s.position(i), frame.toWorld(cosineHemisphere(u1, u2)), offset, kInf});
      }
  }
  return rays;
}

// 16 stratified uniform sphere rays from evenly spread lvoxel centres.
std::vector<Ray> lvoxelGatherRays(const LvoxelSet& l, size_t count) {
  std::vector<Ray> rays;
  if (l.size() == 0) return rays;
  const size_t gathers = std::max<size_t>(1, count / 16);
  for (size_t g = 0; g < gathers; ++g) {
    const size_t i = g * l.size() / gathers;
    Rng rng(13, i);
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) {
        const float u1 = (static_cast<float>(r) + rng.uniform()) * 0.25f;
        const float u2 = (static_cast<float>(c) + rng.uniform()) * 0.25f;
        rays.push_back(Ray{l.position[i], uniformSphere(u1, u2), 0.0f, kInf});
      }
  }
  return rays;
}

// The octree part of ray-traced visibility: each ray from a few tracer epsilons (as
// traceGatherRay starts it) to Embree's hit.
void endAtEmbreesHit(std::vector<Ray>& rays, const RayTracer& tracer) {
  for (Ray& r : rays) {
    r.tmin = 4.0f * tracer.epsilon();
    SurfaceHit hit;
    r.tmax = tracer.intersect(r, hit) ? hit.t : kInf;
  }
}

double threadSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// One thread: a serial loop timed by the thread's CPU clock, so that time spent descheduled
// on a shared machine does not count. More threads: a TBB arena, timed by the wall clock.
template <class PerRay>
double timeRays(size_t n, int threads, const PerRay& perRay) {
  if (threads == 1) {
    const double start = threadSeconds();
    for (size_t k = 0; k < n; ++k) perRay(k);
    return threadSeconds() - start;
  }
  tbb::task_arena arena(threads);
  const auto start = std::chrono::steady_clock::now();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t k = r.begin(); k < r.end(); ++k) perRay(k);
                      });
  });
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

uint64_t combine(const std::vector<uint64_t>& perRay) {
  uint64_t h = 0;
  for (uint64_t v : perRay) h = mixHash(h, v);
  return h;
}

Timing runOctree(const PointCloud& cloud, const Workload& w, const GatherOptions& gather,
                 const GatherOptions& traced, const GatherOptions& searched, int threads) {
  tbb::enumerable_thread_specific<TraversalScratch> scratch;
  std::vector<uint64_t> hashes(w.rays.size());
  const TraversalOptions lvoxelsOnly{traced.maxSolidAngle, traced.maxLvoxelSolidAngle, false};
  Timing t;
  t.seconds = timeRays(w.rays.size(), threads, [&](size_t k) {
    HashSink sink;
    TraversalScratch& s = scratch.local();
    if (w.kind == Kind::Disks) {
      traceGatherRay(cloud, w.rays[k], gather, 1.0f, s, sink);
    } else if (w.kind == Kind::Traced) {
      traceGatherRay(cloud, w.rays[k], traced, 1.0f, s, sink);
    } else if (w.kind == Kind::Searched) {
      traceGatherRay(cloud, w.rays[k], searched, 1.0f, s, sink);
    } else {
      GatherRayWeights<HashSink> weights{cloud, sink, 1.0f, traced.minTransmittance, NearField{}};
      traverse(cloud, w.rays[k], weights, lvoxelsOnly, s);
    }
    hashes[k] = sink.hash;
  });
  t.checksum = combine(hashes);
  uint64_t work = 0, heap = 0;
  for (const TraversalScratch& s : scratch) {
    work += s.stats.nodesPopped + s.stats.cellsMarched + s.stats.elementsTested;
    heap += s.stats.heapRays;
  }
  t.workPerRay = static_cast<double>(work) / static_cast<double>(w.rays.size());
  t.heapShare = static_cast<double>(heap) / static_cast<double>(w.rays.size());
  return t;
}

Timing runEmbree(const RayTracer& tracer, const Workload& w, int threads) {
  std::vector<uint64_t> hashes(w.rays.size());
  Timing t;
  t.seconds = timeRays(w.rays.size(), threads, [&](size_t k) {
    SurfaceHit hit;
    hashes[k] = tracer.intersect(w.rays[k], hit)
                    ? uint64_t(std::bit_cast<uint32_t>(hit.t)) << 32 | hit.triangle
                    : 0;
  });
  t.checksum = combine(hashes);
  return t;
}

// The lattice and the search alone, on the hit points of the surfel gathers' rays in their
// order (random over the scene), one thread: their share of a traced gather ray; and the
// share of hits (on the side the triangle's normal faces and on the other) where the
// lattice gives the search's surfel.
void printHitSurfelsAlone(const TriangleSurfelLattice* lattice, const SurfelLookup& lookup,
                          const RayTracer& tracer, const std::vector<Ray>& rays, int reps) {
  std::vector<SurfaceHit> hits;
  for (Ray r : rays) {
    r.tmin = 4.0f * tracer.epsilon();  // as traceGatherRay starts a traced ray
    SurfaceHit hit;
    if (tracer.intersect(r, hit)) hits.push_back(hit);
  }
  const double n = static_cast<double>(std::max<size_t>(1, hits.size()));
  // The answers' sum is printed: it keeps the queries from being optimised away.
  long sum = 0;
  auto best = [&](const auto& query) {
    double seconds = 1e30;
    for (int rep = 0; rep < reps; ++rep) {
      const double start = threadSeconds();
      for (const SurfaceHit& h : hits) sum += query(h);
      seconds = std::min(seconds, threadSeconds() - start);
    }
    return 1e6 * seconds / n;
  };
  const double searchUs =
      best([&](const SurfaceHit& h) { return lookup.nearest(h.point, h.normal); });
  std::printf("surfel search alone: %.3f us per hit point (%zu hit points, 1 thread, sum %ld)\n",
              searchUs, hits.size(), sum);
  if (!lattice) return;
  sum = 0;
  const double latticeUs = best([&](const SurfaceHit& h) { return lattice->nearest(h); });
  const TriangleMesh& mesh = tracer.mesh();
  size_t side[2] = {0, 0}, same[2] = {0, 0};
  for (const SurfaceHit& h : hits) {
    const Vec3 a = mesh.vertex(h.triangle, 0);
    const Vec3 face = cross(mesh.vertex(h.triangle, 1) - a, mesh.vertex(h.triangle, 2) - a);
    const int back = dot(face, h.normal) < 0.0f ? 1 : 0;
    ++side[back];
    same[back] += lattice->nearest(h) == lookup.nearest(h.point, h.normal);
  }
  auto share = [](size_t k, size_t of) {
    return of ? 100.0 * static_cast<double>(k) / static_cast<double>(of) : 100.0;
  };
  std::printf(
      "surfel lattice alone: %.3f us per hit point (sum %ld); the search's surfel at %.2f %% of "
      "the hits (%.2f %% of %zu on the normal's side, %.2f %% of %zu on the other)\n",
      latticeUs, sum, share(same[0] + same[1], hits.size()), share(same[0], side[0]), side[0],
      share(same[1], side[1]), side[1]);
}

void runScene(const std::string& path, const Args& args) {
  Scene scene = loadScene(path);
  scene.render.mode = Mode::kPcb;
  scene.pointcloud.gatherVisibility = GatherVisibility::kCloud;  // the disks' traversal
  scene.pointcloud.bounces = 0;        // the cloud only: no interreflection ...
  scene.pointcloud.gatherSpacing = 1;  // ... and no final-gather grid
  if (args.surfels > 0) {
    scene.pointcloud.targetSurfels = args.surfels;
    scene.pointcloud.surfelSpacing = 0.0f;
  }
  const float spacing = scene.pointcloud.surfelSpacing > 0.0f
                            ? scene.pointcloud.surfelSpacing
                            : std::sqrt(static_cast<float>(scene.world.mesh.area()) /
                                        static_cast<float>(scene.pointcloud.targetSurfels));
  const RayTracer tracer(scene.world.mesh);
  const LightSet lights(scene.world, scene.render.areaLightSamples);
  const RenderContext ctx{scene.world, scene.render, tracer, lights};
  Report report;
  const MediaSet media = MediaSet::build(scene.media, scene.volume.interpolation, report.warnings);
  const VolumeTransport volume(ctx, media, scene.volume);
  const auto build = std::chrono::steady_clock::now();
  const PointBasedCache cache = buildPointCloud(ctx, volume, scene.pointcloud, scene.path, report);
  const double buildSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - build).count();
  const PointCloud& cloud = *cache.cloud;

  // The gathers' options, as pcb_integrator.cpp sets them (disk visibility), each
  // visibility with its own default lvoxel clusters.
  GatherOptions gather;
  gather.maxSolidAngle = scene.pointcloud.clusterSolidAngle;
  gather.maxLvoxelSolidAngle = defaultLvoxelClusterSolidAngle(GatherVisibility::kCloud);
  gather.rayOffset = 0.25f * spacing;
  gather.background = RGB(0.0f);
  // Ray-traced visibility (the default): Embree finds the surface, the triangle lattice
  // its surfel (as buildPointCloud builds it); "searched": the exact search instead.
  const SurfelLookup lookup(cloud.surfels(), spacing);
  const float latticeStep = scene.pointcloud.hitLatticeStep * spacing;
  const auto latticeStart = std::chrono::steady_clock::now();
  std::unique_ptr<TriangleSurfelLattice> lattice;
  if (latticeStep > 0.0f)
    lattice = std::make_unique<TriangleSurfelLattice>(scene.world.mesh, lookup, latticeStep);
  const double latticeSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - latticeStart).count();
  GatherOptions searchedGather = gather;
  searchedGather.tracer = &tracer;
  searchedGather.lookup = &lookup;
  searchedGather.maxLvoxelSolidAngle = defaultLvoxelClusterSolidAngle(GatherVisibility::kRays);
  GatherOptions tracedGather = searchedGather;
  tracedGather.lattice = lattice.get();

  std::vector<Workload> workloads;
  workloads.push_back({"surfel gathers (disks)", Kind::Disks,
                       surfelGatherRays(cloud.surfels(), args.rays, gather.rayOffset)});
  if (cloud.lvoxels().size() > 0) {
    // Ray-traced visibility: the octree for the lvoxels in front of Embree's hit.
    Workload traced{"surfel gathers (lvoxels)", Kind::LvoxelsOnly, workloads[0].rays};
    endAtEmbreesHit(traced.rays, tracer);
    workloads.push_back(std::move(traced));
  }
  workloads.push_back({"surfel gathers (traced)", Kind::Traced, workloads[0].rays});
  if (lattice)
    workloads.push_back({"surfel gathers (searched)", Kind::Searched, workloads[0].rays});
  if (cloud.lvoxels().size() > 0) {
    Workload disks{"lvoxel gathers (disks)", Kind::Disks,
                   lvoxelGatherRays(cloud.lvoxels(), args.rays)};
    Workload lvoxels{"lvoxel gathers (lvoxels)", Kind::LvoxelsOnly, disks.rays};
    endAtEmbreesHit(lvoxels.rays, tracer);
    Workload traced{"lvoxel gathers (traced)", Kind::Traced, disks.rays};
    workloads.push_back(std::move(disks));
    workloads.push_back(std::move(lvoxels));
    workloads.push_back(std::move(traced));
  }

  std::printf(
      "\n%s: %zu triangles, %zu surfels (spacing %.4g), %zu lvoxels, %zu nodes, "
      "cloud built in %.2f s, traversal layout %.1f MB of %.1f MB (lvoxel lattice %.2f MB)\n",
      std::filesystem::path(path).filename().c_str(), scene.world.mesh.triangleCount(),
      cloud.surfels().size(), spacing, cloud.lvoxels().size(), cloud.nodes().size(), buildSeconds,
      static_cast<double>(cloud.traversalBytes()) * 1e-6,
      static_cast<double>(cloud.memoryBytes()) * 1e-6,
      cloud.lvoxelLattice() ? static_cast<double>(cloud.lvoxelLattice()->memoryBytes()) * 1e-6
                            : 0.0);
  if (lattice)
    std::printf(
        "surfel lattice: step %.2f surfel spacings, %zu points (%.2f per surfel), %.1f MB, "
        "built in %.2f s (%d threads)\n",
        static_cast<double>(scene.pointcloud.hitLatticeStep), lattice->points(),
        static_cast<double>(lattice->points()) /
            static_cast<double>(std::max<size_t>(1, cloud.surfels().size())),
        static_cast<double>(lattice->memoryBytes()) * 1e-6, latticeSeconds,
        tbb::info::default_concurrency());
  std::printf("%-26s %7s %8s %14s %14s %7s %9s %6s  %s\n", "workload", "threads", "rays",
              "octree Mrays/s", "embree Mrays/s", "ratio", "work/ray", "heap", "checksum");
  for (const Workload& w : workloads)
    for (int threads : args.threads) {
      Timing octree, embree;
      for (int rep = 0; rep < args.reps; ++rep) {
        const Timing o = runOctree(cloud, w, gather, tracedGather, searchedGather, threads);
        const Timing e = runEmbree(tracer, w, threads);
        if (o.seconds < octree.seconds) octree = o;
        if (e.seconds < embree.seconds) embree = e;
      }
      const double n = static_cast<double>(w.rays.size());
      const double octreeRate = n / octree.seconds, embreeRate = n / embree.seconds;
      std::printf("%-26s %7d %8zu %14.3f %14.3f %7.3f %9.1f %5.1f%%  %016llx\n", w.name, threads,
                  w.rays.size(), octreeRate * 1e-6, embreeRate * 1e-6, octreeRate / embreeRate,
                  octree.workPerRay, 100.0 * octree.heapShare,
                  static_cast<unsigned long long>(octree.checksum));
    }
  printHitSurfelsAlone(lattice.get(), lookup, tracer, workloads[0].rays, args.reps);
}

int usage(const char* argv0) {
  std::fprintf(stderr,
               "usage: %s [--rays N] [--reps R] [--threads 1,2] [--surfels N] [SCENE.json ...]\n",
               argv0);
  return 2;
}

}  // namespace
}  // namespace lvox

int main(int argc, char** argv) {
  using namespace lvox;
  Args args;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool hasValue = i + 1 < argc;
    if (a == "--rays" && hasValue) {
      args.rays = std::strtoull(argv[++i], nullptr, 10);
    } else if (a == "--reps" && hasValue) {
      args.reps = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--surfels" && hasValue) {
      args.surfels = std::atoi(argv[++i]);
    } else if (a == "--threads" && hasValue) {
      for (const char* p = argv[++i]; *p;) {
        char* end;
        const long t = std::strtol(p, &end, 10);
        if (end == p) return usage(argv[0]);
        args.threads.push_back(static_cast<int>(t));
        p = *end == ',' ? end + 1 : end;
      }
    } else if (!a.empty() && a[0] == '-') {
      return usage(argv[0]);
    } else {
      args.scenes.push_back(a);
    }
  }
  if (args.threads.empty()) args.threads = {1, tbb::info::default_concurrency()};
  if (args.scenes.empty()) {
    const std::string dir = LVOX_SOURCE_DIR "/scenes/";
    args.scenes = {dir + "atrium.json", dir + "atrium_smoke.json"};
    if (std::filesystem::exists(LVOX_SOURCE_DIR "/../shared/assets/sponza/sponza.obj"))
      args.scenes.push_back(dir + "sponza.json");
  }
  try {
    for (const std::string& s : args.scenes) runScene(s, args);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lvox_gather_speed: %s\n", e.what());
    return 1;
  }
  return 0;
}
