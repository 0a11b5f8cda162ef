#include "src/render/pcb_integrator.h"

#include <tbb/combinable.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <stdexcept>

#include "pointcloud/buried_surfels.h"
#include "pointcloud/cube_transmittance.h"
#include "pointcloud/gather.h"
#include "pointcloud/light_cache.h"
#include "pointcloud/surfel_sampler.h"
#include "src/core/error.h"
#include "src/render/camera_layers.h"
#include "src/render/cloud_exchange.h"
#include "src/render/direct_integrator.h"
#include "src/render/emitter_pixels.h"
#include "src/render/pcb_media.h"
#include "src/render/surface_albedo.h"
#include "src/render/surface_direct.h"

namespace lvox {
namespace {

float surfelSpacing(const World& world, const PointCloudSettings& settings) {
  if (settings.surfelSpacing > 0.0f) return settings.surfelSpacing;
  return std::sqrt(static_cast<float>(world.mesh.area()) /
                   static_cast<float>(settings.targetSurfels));
}

// What the point cloud holds per element, measured on Sponza with smoke at 2.8 M surfels
// (docs/results.md, "Scale and memory": 954 MB peak, 320 bytes per surfel in all): beside
// the interreflection weights, a surfel costs about 250 bytes at the peak (itself, its
// share of the octree and its packed disk, the surfel lookup, the passes' snapshot and
// direct copies); a weight 6 bytes (its column and a half float), about 1.2 per surfel
// gather ray and 16 per lvoxel gather ray (grey weights; coloured ones take 16 bytes and
// are reserved as they are stored). The sampler adds border sites: up to 15 % more surfels than
// area / spacing^2.
constexpr double kBytesPerSurfel = 250.0, kBytesPerLvoxel = 250.0, kBytesPerWeight = 6.0;
constexpr double kWeightsPerSurfelRay = 1.2, kWeightsPerLvoxelRay = 16.0, kBorderSites = 1.15;
// Directional lvoxels (anisotropic media) add 8 coefficients per colour in each of their
// cell's three light arrays (288 bytes) and in their share of the clusters (about 0.3 node
// per lvoxel on the WDAS cloud, 32 bytes).
constexpr double kDirectionalBytesPerLvoxel = 320.0;
// Indices into the octree's packed arrays have 29 bits (octree_node.h).
constexpr double kMaxSurfels = 2.5e8;

const char* surfelCountField(const PointCloudSettings& settings) {
  return settings.surfelSpacing > 0.0f ? "pointcloud.surfel_spacing" : "pointcloud.target_surfels";
}

// The surfels a spacing asks for, checked before any is sampled: a spacing far too small
// for the surfaces is an input error, not hours of sampling or an allocation failure.
void checkSurfelMemory(const RenderContext& ctx, const PointCloudSettings& settings, float spacing,
                       const std::string& sceneFile) {
  if (!(spacing > 0.0f) || settings.surfelSampler == SurfelSamplerKind::kCamera) return;
  const double estimate =
      kBorderSites * ctx.world.mesh.area() / (static_cast<double>(spacing) * spacing);
  if (estimate > kMaxSurfels)
    throw InputError(sceneFile, surfelCountField(settings),
                     "asks for about " + std::to_string(static_cast<long long>(estimate)) +
                         " surfels over " + std::to_string(ctx.world.mesh.area()) +
                         " square units (at most 250,000,000)");
  if (!ctx.budget) return;
  const double weights = settings.bounces > 0 ? 2.0 * settings.surfelGatherSamples *
                                                    kWeightsPerSurfelRay * kBytesPerWeight
                                              : 0.0;
  const std::string what =
      "the point cloud (about " + std::to_string(static_cast<long long>(estimate)) + " surfels)";
  ctx.budget->check(static_cast<uint64_t>(estimate * (kBytesPerSurfel + weights)), sceneFile,
                    surfelCountField(settings), what);
  ctx.budget->reserve(static_cast<uint64_t>(estimate * kBytesPerSurfel), sceneFile,
                      surfelCountField(settings), what);
}

// The lvoxels, once sampled (their count depends on the media): their light, their share
// of the octree and their interreflection weights.
void checkLvoxelMemory(const RenderContext& ctx, const PointCloudSettings& settings,
                       const LvoxelSet& set, const std::string& sceneFile) {
  const size_t lvoxels = set.size();
  if (!ctx.budget || lvoxels == 0) return;
  const double n = static_cast<double>(lvoxels);
  const double perLvoxel =
      kBytesPerLvoxel + (set.light.coefficients() > 1 ? kDirectionalBytesPerLvoxel : 0.0);
  GatherOptions near;  // its short near-field rays meet about one lvoxel per cube side
  near.samples = settings.lvoxelGatherSamples;
  near.nearSamples = settings.lvoxelNearSamples;
  near.nearReach = settings.lvoxelNearReach;
  const double nearWeights =
      nearFieldRaysPerRay(near) * (std::ceil(settings.lvoxelNearReach) + 1.0);
  const double weights =
      settings.bounces > 0
          ? settings.lvoxelGatherSamples * (kWeightsPerLvoxelRay + nearWeights) * kBytesPerWeight
          : 0.0;
  const std::string what = "the lvoxels (" + std::to_string(lvoxels) + ")";
  ctx.budget->check(static_cast<uint64_t>(n * (perLvoxel + weights)), sceneFile,
                    "pointcloud.lvoxel_spacing", what);
  ctx.budget->reserve(static_cast<uint64_t>(n * perLvoxel), sceneFile, "pointcloud.lvoxel_spacing",
                      what);
}

// `seeSky`: the rays that leave the cloud see the constant environment (its light is not
// in the receivers' direct light then: PointBasedCache::environmentInGathers).
GatherOptions gatherOptions(const RenderContext& ctx, const PointBasedCache& cache,
                            const PointCloudSettings& settings, float spacing, int samples,
                            bool seeSky = false) {
  GatherOptions o;
  o.samples = samples;
  o.maxSolidAngle = settings.clusterSolidAngle;
  o.maxLvoxelSolidAngle = settings.lvoxelClusterSolidAngle;
  // Gather rays start a quarter spacing out, past the receiver's own (possibly tilted)
  // disk. Neighbouring disks of a curved surface are passed by their enclosed inner sides
  // (buried_surfels.h), so the offset need not skip them: half a spacing skipped real
  // nearby geometry too (4.02 % against 3.88 % delta on the atrium, docs/results.md).
  o.rayOffset = 0.25f * spacing;
  o.background = seeSky ? ctx.lights.environment() : RGB(0.0f);
  if (cache.lattice || cache.lookup) {
    o.tracer = &ctx.tracer;
    o.lattice = cache.lattice.get();
    o.lookup = cache.lookup.get();
    o.hitLight = cache.hitLight.get();
  }
  return o;
}

// The final gathers' options: `samples` rays, the cells' share of them as the settings'
// share of gather_samples, or of 64 under auto (gatherLightSamplesBase; a pixel's gathers
// split over its samples split both kinds).
GatherOptions finalGatherOptions(const RenderContext& ctx, const PointBasedCache& cache,
                                 const PointCloudSettings& settings, float spacing, int samples) {
  GatherOptions o =
      gatherOptions(ctx, cache, settings, spacing, samples, cache.environmentInGathers);
  o.lights = cache.gatherLights.get();
  o.lightSamples = static_cast<int>(static_cast<long>(settings.gatherLightSamples) * samples /
                                    gatherLightSamplesBase(settings));
  return o;
}

// The lit surfaces' cells for the final gathers, about two surfel spacings across: about
// one cell per surfel on large triangles (a right isosceles one of m x m cells has
// 4 area / step^2 of them), one at least on each small one (3.3 per surfel on Sponza),
// fine enough to pick out a lamp's bright spot, which spans many surfels.
constexpr float kLightCellSpacings = 2.0f;

void buildGatherLights(const RenderContext& ctx, const PointCloudSettings& settings, float spacing,
                       const std::string& sceneFile, PointBasedCache& cache, Report& report) {
  if (settings.gatherLightSamples <= 0 || !(cache.lattice || cache.lookup)) return;
  PhaseTimer timer(report, "gather_light_cells");
  const float step = kLightCellSpacings * spacing;
  const size_t cells = GatherLightCells::cellsFor(ctx.world.mesh, step);
  const char* field = "pointcloud.gather_light_samples";
  if (cells >= (size_t{1} << 31))  // two sides per cell, indexed in 32 bits
    throw InputError(sceneFile, field,
                     "the lit surfaces' cells would number " + std::to_string(cells) +
                         ", 2^31 or more; raise the surfel spacing or set it to 0");
  if (ctx.budget)
    ctx.budget->check(GatherLightCells::bytesFor(cells, ctx.world.mesh.triangleCount()), sceneFile,
                      field, "the lit surfaces' cells (" + std::to_string(cells) + ")");
  const GatherOptions options = gatherOptions(ctx, cache, settings, spacing, 1);
  cache.gatherLights =
      std::make_unique<GatherLightCells>(ctx.world.mesh, *cache.cloud, options, step);
  report.add("gather_light_cells", cache.gatherLights->cells());
  report.add("gather_light_regions", cache.gatherLights->regions());
  report.memory["gather_light_cells"] = cache.gatherLights->memoryBytes();
}

// Ray-traced visibility's surfel at each gather hit: the exact lookup, and from it the
// triangle lattice unless "hit_lattice_step" is 0. The lookup is dropped once the lattice
// holds its answers: the gathers read the lattice only.
void buildHitSurfels(const RenderContext& ctx, const PointCloudSettings& settings, float spacing,
                     const std::string& sceneFile, PointBasedCache& cache) {
  auto lookup = std::make_unique<SurfelLookup>(cache.cloud->surfels(), spacing);
  if (settings.hitLatticeStep <= 0.0f) {
    cache.lookup = std::move(lookup);
    return;
  }
  const float step = settings.hitLatticeStep * spacing;
  const size_t points = TriangleSurfelLattice::pointsFor(ctx.world.mesh, step);
  const char* field = "pointcloud.hit_lattice_step";
  if (points > std::numeric_limits<uint32_t>::max())
    throw InputError(sceneFile, field,
                     "the surfel lattice would need " + std::to_string(points) +
                         " points, more than 2^32 - 1; raise the step or the surfel spacing");
  if (ctx.budget)
    ctx.budget->check(TriangleSurfelLattice::bytesFor(points, ctx.world.mesh.triangleCount()),
                      sceneFile, field,
                      "the surfel lattice (" + std::to_string(points) + " points)");
  cache.lattice = std::make_unique<TriangleSurfelLattice>(ctx.world.mesh, *lookup, step);
}

// The surfels one process samples, each sampled once across the ranks (cloud_exchange.h):
// with the uniform sampler each rank samples the triangles of its slice and the slices are
// exchanged; the camera sampler (one grid of camera rays, cheap next to the burial probes)
// runs on every rank.
SurfelSet sampleSurfelSlices(const RenderContext& ctx, SurfelSamplerKind sampler, float spacing,
                             const std::string& sceneFile, const PointCloudSettings& settings,
                             Collective& team, Report& report) {
  const World& world = ctx.world;
  if (!(spacing > 0.0f)) return {};  // no surfaces (a scene of media only)
  if (sampler == SurfelSamplerKind::kCamera)
    return sampleSurfelsFromCamera(
        ctx.tracer, world.materials, world.camera,
        CameraSurfelSettings{0.1f, 2.0f, 1.15f, 0.1f, ctx.settings.seed});
  UniformSurfelSettings uniform;
  uniform.spacing = spacing;
  uniform.seed = ctx.settings.seed;
  if (team.distributed()) {
    const std::vector<size_t> slices = triangleSlices(world.mesh, team.size());
    uniform.firstTriangle = slices[static_cast<size_t>(team.rank())];
    uniform.endTriangle = slices[static_cast<size_t>(team.rank()) + 1];
  }
  report.work["surfel_triangles"] +=
      std::min(uniform.endTriangle, world.mesh.triangleCount()) - uniform.firstTriangle;
  SurfelSet slice =
      sampleSurfelsUniform(world.mesh, world.materials, uniform, ctx.tracer.textures());
  report.work["surfels_sampled"] += slice.size();
  if (!team.distributed()) return slice;
  PhaseTimer timer(report, "cloud_exchange");
  if (ctx.budget)  // the bytes of every slice and the whole set they become, for a moment
    ctx.budget->check(
        2 * slice.size() * static_cast<uint64_t>(team.size()) * SurfelSet::bytesPerElement(),
        sceneFile, surfelCountField(settings), "the surfels exchanged between ranks");
  return allgatherSurfels(std::move(slice), team);
}

// Marks and removes the buried surfels (buried_surfels.h), each rank probing an equal range
// of them and the marks exchanged (one byte per surfel).
void removeBuried(const RenderContext& ctx, float reach, SurfelSet& surfels, Collective& team,
                  Report& report) {
  if (!(reach > 0.0f) || surfels.size() == 0) return;
  const BuriedSurfelSettings burial{reach, 16, ctx.settings.seed, ctx.world.camera.position};
  const auto share = [&](int r) {
    return surfels.size() * static_cast<size_t>(r) / static_cast<size_t>(team.size());
  };
  const size_t begin = share(team.rank()), end = share(team.rank() + 1);
  markEnclosedSides(surfels, ctx.tracer, burial, begin, end);
  report.work["surfels_probed"] += end - begin;
  if (team.distributed()) {
    PhaseTimer timer(report, "cloud_exchange");
    const std::string mine(reinterpret_cast<const char*>(surfels.enclosedSides.data() + begin),
                           end - begin);
    const std::vector<std::string> all = team.allgather(mine);
    for (int r = 0; r < team.size(); ++r) {
      const std::string& marks = all[static_cast<size_t>(r)];
      if (marks.size() != share(r + 1) - share(r))
        throw std::runtime_error("the burial marks received from rank " + std::to_string(r) + ": " +
                                 std::to_string(marks.size()) + " bytes, expected " +
                                 std::to_string(share(r + 1) - share(r)));
      std::copy(marks.begin(), marks.end(),
                reinterpret_cast<char*>(surfels.enclosedSides.data() + share(r)));
    }
  }
  report.add("buried_surfels", removeEnclosedSurfels(surfels));
}

// The cloud whose lvoxels' cubes the shadow rays of the indirect light cross
// (pointcloud.indirect_shadow_media), or null for the media themselves. The cubes hold
// the media as the cloud's light sees them: reduced where the lvoxels are directional,
// as cache.reducedShadows asks of the media's own shadow rays.
const PointCloud* indirectShadowCubes(const PointBasedCache& cache,
                                      const PointCloudSettings& settings) {
  return cache.lvoxels && settings.indirectShadowMedia == IndirectShadowMedia::kCubes
             ? cache.cloud.get()
             : nullptr;
}

// Direct light on surfels (exact shadow rays, transmittance through the media or the
// cubes) and on lvoxel cells (their light, pcb_media.h), each with its own number of
// area-light and sky samples (pointcloud.surfel_light_samples and lvoxel_light_samples).
void cacheDirect(const RenderContext& ctx, const VolumeTransport& volume,
                 const PointCloudSettings& settings, PointBasedCache& cache,
                 rte::SolveCounts& counts, Collective& team, Report& report) {
  PointCloud& cloud = *cache.cloud;
  LvoxelLight& lvoxelLight = cloud.mutableLvoxels().light;
  // The same lights with the cloud's own number of area and sky samples.
  const auto withSamples = [&](const LightSet& lights) {
    return RenderContext{ctx.world, ctx.settings, ctx.tracer, lights, ctx.budget};
  };
  if (cache.lvoxels) {
    PhaseTimer timer(report, "lvoxel_direct");  // a part of "direct_cache"
    const LightSet lvoxelLights(ctx.world, settings.lvoxelLightSamples);
    lvoxelLight.setBlend(settings.lvoxelLightBlend);
    report.work["lvoxel_direct_cells"] += cacheLvoxelDirectLight(
        withSamples(lvoxelLights), volume, lvoxelLight, counts, team,
        settings.lvoxelSkyShadowMedia == IndirectShadowMedia::kCubes ? &cloud : nullptr);
  }
  const LightSet surfelLights(ctx.world, settings.surfelLightSamples);
  const RenderContext surfelCtx = withSamples(surfelLights);
  const PointCloud* cubes = indirectShadowCubes(cache, settings);
  tbb::combinable<rte::SolveCounts> perThread;
  cacheDirectLight(
      cloud,
      [&](const SurfelLightQuery& q) {
        SurfaceHit hit;
        hit.point = q.position;
        hit.normal = q.normal;
        hit.shading = q.normal;
        Rng rng(ctx.settings.seed ^ 0x5eedu,
                (static_cast<uint64_t>(q.index) << 1) |
                    (dot(q.normal, cloud.surfels().normal(q.index)) < 0));
        rte::SolveCounts& local = perThread.local();
        auto throughMedia = [&](const Ray& shadow) {
          if (cubes) {
            thread_local TraversalScratch scratch;
            return cubeTransmittance(*cubes, shadow, scratch);
          }
          return volume.transmittance(shadow, local, cache.reducedShadows);
        };
        uint64_t rays = 0;
        // Reflected light only: an emissive surface's own emission reaches every receiver
        // as an area light (surfaceDirect, the lvoxels' area samples), so a surfel that
        // also carried it would hand it out a second time through every gather.
        // With a hit light the gathers take the delta lights' light at their hits, and the
        // sky may come through their escaping rays.
        const LightSubset lights{.delta = !cache.hitLight,
                                 .constantEnvironment = !cache.surfelEnvironmentInGathers};
        return surfaceDirect(surfelCtx, hit, q.albedo, rng, throughMedia, rays, lights);
      },
      [&](const LvoxelLightQuery& q, RGB* out) {
        cloudDirectLight(ctx.lights, lvoxelLight, q.slot, out);
      },
      team);
  perThread.combine_each([&](const rte::SolveCounts& c) { counts += c; });
}

void reportCloud(const PointBasedCache& cache, float spacing, Report& report) {
  const PointCloud& cloud = *cache.cloud;
  const PointCloudMemory mem = cloud.memory();
  report.add("surfels", cloud.surfels().size());
  report.add("lvoxels", cloud.lvoxels().size());
  report.add("octree_nodes", cloud.nodes().size());
  report.memory["surfels"] = mem.surfelBytes;
  report.memory["lvoxels"] = mem.lvoxelBytes;
  report.memory["point_cloud"] = mem.surfelBytes + mem.lvoxelBytes;
  report.memory["octree"] = mem.octreeBytes;
  report.memory["lvoxel_light"] = cloud.lvoxels().light.memoryBytes();
  // Without their border cuts: the traversal layout keeps those of the disks that are cut.
  report.memory["bytes_per_surfel"] = CloudSurfels::bytesPerElement();
  report.memory["bytes_per_lvoxel"] = LvoxelSet::bytesPerElement();
  report.memory["bytes_per_node"] = cloud.bytesPerNode();
  const uint64_t hitSurfelBytes = (cache.lookup ? cache.lookup->memoryBytes() : 0) +
                                  (cache.lattice ? cache.lattice->memoryBytes() : 0);
  if (cache.lookup) report.memory["surfel_lookup"] = cache.lookup->memoryBytes();
  if (cache.lattice) {
    report.memory["surfel_lattice"] = cache.lattice->memoryBytes();
    report.add("surfel_lattice_points", cache.lattice->points());
  }
  // Everything the cloud holds per element: the elements, the octree (nodes, clusters,
  // traversal layout), the surfel lattice or lookup, the lvoxel light and the
  // interreflection weights.
  const uint64_t elements = cloud.surfels().size() + cloud.lvoxels().size();
  const auto weights = report.memory.find("interreflection_operator");
  const uint64_t held = mem.total() + hitSurfelBytes + cloud.lvoxels().light.memoryBytes() +
                        (weights == report.memory.end() ? 0 : weights->second);
  if (elements > 0) report.memory["bytes_per_element"] = (held + elements / 2) / elements;
  report.settings["surfel_spacing"] = std::to_string(spacing);
  if (cache.lvoxels)
    report.settings["lvoxel_spacing"] = std::to_string(cloud.lvoxels().light.grid().spacing);
}

}  // namespace

PointBasedCache buildPointCloud(const RenderContext& ctx, const VolumeTransport& volume,
                                const PointCloudSettings& settings, const std::string& sceneFile,
                                Report& report, Collective& team) {
  const uint64_t seed = ctx.settings.seed;
  const float spacing = surfelSpacing(ctx.world, settings);
  checkSurfelMemory(ctx, settings, spacing, sceneFile);
  PointBasedCache cache;
  cache.lvoxels = ctx.settings.mode == Mode::kPcb && !volume.empty();
  SurfelSet surfels;
  {
    PhaseTimer timer(report, "surfel_sampling");
    surfels =
        sampleSurfelSlices(ctx, settings.surfelSampler, spacing, sceneFile, settings, team, report);
    removeBuried(ctx, settings.burialReach * spacing, surfels, team, report);
  }
  LvoxelSet lvoxels;
  if (cache.lvoxels) {
    PhaseTimer timer(report, "lvoxel_sampling");
    size_t sampled = 0;
    // Anisotropic media make directional lvoxels when the cloud carries multiple
    // scattering (pcb_media.h); with no bounces they hold the exact single scattering.
    const bool directional = settings.bounces > 0 && anisotropicLvoxels(volume.media());
    lvoxels = sampleSceneLvoxels(volume.media(),
                                 lvoxelSpacing(settings.lvoxelSpacing, volume.media(), sceneFile),
                                 settings.lvoxelSamples, settings.lvoxelExtinction, seed,
                                 ctx.lights, directional, team, &sampled);
    report.work["lvoxels_sampled"] += sampled;
    // Media whose coefficients average to zero everywhere give no lvoxels: nothing is
    // cached, and camera rays keep the exact (and then trivial) single-scattering path.
    cache.lvoxels = lvoxels.size() > 0;
    cache.reducedShadows = cache.lvoxels && lvoxels.light.coefficients() > 1;
    checkLvoxelMemory(ctx, settings, lvoxels, sceneFile);
  }
  {
    PhaseTimer timer(report, "octree_build");
    OctreeSettings octree;
    // Surfel clusters are read by gathers that find surfaces in the cloud only.
    octree.surfelClusters =
        settings.clusterSolidAngle > 0.0f && settings.gatherVisibility == GatherVisibility::kCloud;
    cache.cloud = std::make_unique<PointCloud>(std::move(surfels), std::move(lvoxels), octree);
    if (settings.gatherVisibility == GatherVisibility::kRays) {
      if (cache.lvoxels) {
        const CutLvoxels cut = markCutLvoxels(ctx.tracer, *cache.cloud);
        report.add("lvoxels_cut", cut.lvoxels);
        report.add("lvoxel_cells_near_surfaces", cut.cells);
      }
      buildHitSurfels(ctx, settings, spacing, sceneFile, cache);
      if (!ctx.lights.lights().empty())
        cache.hitLight = std::make_unique<DeltaHitLight>(ctx, volume, cache.reducedShadows,
                                                         indirectShadowCubes(cache, settings));
      cache.environmentInGathers = !isBlack(ctx.lights.environment());
      cache.surfelEnvironmentInGathers = cache.environmentInGathers && settings.bounces > 0;
    }
  }
  rte::SolveCounts counts;
  {
    PhaseTimer timer(report, "direct_cache");
    cacheDirect(ctx, volume, settings, cache, counts, team, report);
  }
  const int passes = settings.bounces;
  uint64_t cloudGatherRays = 0;
  if (passes > 0) {
    PhaseTimer timer(report, "interreflection");
    const GatherOptions surfelOptions =
        gatherOptions(ctx, cache, settings, spacing, settings.surfelGatherSamples,
                      cache.surfelEnvironmentInGathers);
    GatherOptions lvoxelOptions =
        gatherOptions(ctx, cache, settings, spacing, settings.lvoxelGatherSamples);
    lvoxelOptions.rayOffset = 0.0f;  // an lvoxel's own cube is part of its neighbourhood
    lvoxelOptions.nearSamples = settings.lvoxelNearSamples;
    lvoxelOptions.nearReach =
        settings.lvoxelNearReach * cache.cloud->lvoxels().light.grid().spacing;
    lvoxelOptions.ownCubeQuadrature = settings.lvoxelOwnCube == LvoxelOwnCube::kQuadrature;
    std::function<void(uint64_t)> reserve;
    if (ctx.budget)
      reserve = [&](uint64_t bytes) {
        ctx.budget->reserve(bytes, sceneFile, "pointcloud.surfel_gather_samples",
                            "the interreflection's weights");
      };
    std::function<bool(uint64_t)> reserveMixing;
    if (ctx.budget)
      reserveMixing = [&](uint64_t bytes) {
        if (settings.bounceMixingDepth == kAutoBounceMixing) return ctx.budget->tryReserve(bytes);
        ctx.budget->reserve(bytes, sceneFile, "pointcloud.bounce_mixing_depth",
                            "the passes' mixing");
        return true;
      };
    const InterreflectionPasses plan(passes, settings.bounceTolerance,
                                     settings.bounceTail == BounceTail::kGeometric,
                                     settings.bounceMixingDepth);
    uint64_t previewRays = 0;
    const auto previewStart = std::chrono::steady_clock::now();
    const SurfelRays sideRays =
        settings.surfelGatherAllocation == SurfelRayAllocation::kVariance
            ? previewSurfelRays(*cache.cloud, IsotropicPhase{}, surfelOptions, lvoxelOptions, plan,
                                settings.surfelGatherSamples, seed, team, previewRays)
            : uniformSurfelRays(cache.cloud->surfels().size(), settings.surfelGatherSamples, seed);
    const double previewSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - previewStart).count();
    const InterreflectionStats stats =
        cacheInterreflection(*cache.cloud, IsotropicPhase{}, surfelOptions, lvoxelOptions, plan,
                             seed, team, reserve, &sideRays, reserveMixing);
    cloudGatherRays = stats.gatherRays;
    report.add("cache_preview_rays", previewRays);
    report.add("cache_gather_rays", stats.gatherRays);
    report.add("interreflection_weights", stats.entries);
    report.memory["interreflection_operator"] = stats.operatorBytes;
    report.settings["interreflection_last_pass_change"] = std::to_string(stats.lastPassChange);
    std::string changes;  // three digits each: the late passes change by 1e-5 and less
    for (double c : stats.passChanges) {
      char digits[32];
      std::snprintf(digits, sizeof digits, "%s%.3g", changes.empty() ? "" : ",", c);
      changes += digits;
    }
    report.settings["interreflection_pass_changes"] = changes;
    report.settings["interreflection_passes"] = std::to_string(stats.passes);
    report.settings["interreflection_ratio"] = std::to_string(stats.ratio);
    report.settings["interreflection_tail"] = std::to_string(stats.tail);
    report.settings["interreflection_mixed_passes"] = std::to_string(stats.mixedPasses);
    if (plan.mayMix())  // what auto mixing decided from
      report.settings["interreflection_predicted_passes"] = std::to_string(stats.predictedPasses);
    // Parts of "interreflection": the rest is the passes' products and updates.
    report.times["interreflection_trace"] = stats.traceSeconds;
    report.times["interreflection_preview"] = previewSeconds;
    if (team.distributed()) report.times["interreflection_exchange"] = stats.exchangeSeconds;
  }
  if (team.distributed()) {  // each rank counted the direct light of its own elements
    std::vector<uint64_t> evals{counts.mediumEvals};
    team.sum(evals);
    counts.mediumEvals = evals[0];
  }
  report.add("cache_medium_evals", counts.mediumEvals);
  reportCloud(cache, spacing, report);
  buildGatherLights(ctx, settings, spacing, sceneFile, cache, report);
  const Camera& camera = ctx.world.camera;
  const uint64_t finalGatherPoints =
      settings.gatherSpacing > 1
          ? IndirectGrid::pointsFor(camera.width, camera.height, settings.gatherSpacing)
          : static_cast<uint64_t>(camera.width) * static_cast<uint64_t>(camera.height);
  cache.gatherSamples = finalGatherSamples(settings, cloudGatherRays, finalGatherPoints);
  report.settings["final_gather_samples"] = std::to_string(cache.gatherSamples);
  if (settings.gatherSpacing > 1) {
    PhaseTimer timer(report, "gather_grid");
    const GatherOptions options =
        finalGatherOptions(ctx, cache, settings, spacing, cache.gatherSamples);
    cache.gathers = IndirectGrid(ctx, *cache.cloud, options, settings.gatherSpacing,
                                 settings.gatherFilter, settings.gatherFit, seed, team);
    report.add("grid_gathers", cache.gathers.pointCount());
    report.add("grid_gather_rays",
               cache.gathers.pointCount() * static_cast<uint64_t>(options.samples));
  }
  if (cache.hitLight) {  // the interreflection's and the screen grid's gather hits
    const DeltaHitLight::Counts total = cache.hitLight->total();
    std::vector<uint64_t> hits{total.shadowRays, total.solve.mediumEvals};
    team.sum(hits);  // each rank traced its own rows
    report.add("gather_hit_shadow_rays", hits[0]);
    report.add("gather_hit_medium_evals", hits[1]);
  }
  return cache;
}

PixelSampler pcbSampler(const RenderContext& ctx, const VolumeTransport& volume,
                        const PointBasedCache& cache, const PointCloudSettings& settings, int spp,
                        SamplerCounters& counters) {
  const int perSample = std::max(1, cache.gatherSamples / std::max(1, spp));
  const GatherOptions options =
      finalGatherOptions(ctx, cache, settings, surfelSpacing(ctx.world, settings), perSample);
  const LightSubset atHits{.constantEnvironment = !cache.environmentInGathers};
  auto emitters = std::make_shared<const EmitterPixels>(ctx, ctx.settings.emitterSamples);
  const CameraShadowRays cameraShadowRays = settings.cameraShadowRays;
  return [&ctx, &volume, &cache, &counters, options, atHits, emitters, cameraShadowRays](
             const PixelSample& s, Rng& rng, SampleLayers* layers) {
    const World& world = ctx.world;
    const float px = s.filmX, py = s.filmY;
    const Ray ray = world.camera.generateRay(px, py);
    rte::SolveCounts solveCounts;
    SurfaceHit hit;
    const bool hitSurface = ctx.tracer.intersect(ray, hit);
    // On an emitter's edge what comes straight from the lights (the emitters' emission and
    // the light surfaces reflect from them) comes from rays of its own (below).
    const bool edge = emitters->covers(s.x, s.y);
    auto throughMedia = [&](const Ray& shadow) {
      return volume.transmittance(shadow, solveCounts, cache.reducedShadows);
    };
    uint64_t shadowRays = 0;
    RGB environment(0.0f), emission(0.0f), direct(0.0f), indirect(0.0f);
    if (hitSurface) {
      const Material& m = world.materials[world.mesh.triangleMaterial[hit.triangle]];
      // The cloud carries irradiance; the texture multiplies it here, at the pixel's own
      // footprint, so texture detail is never blurred to the surfel spacing.
      const RGB albedo = cameraHitAlbedo(ctx, m, ray, hit);
      if (!edge) direct = surfaceDirect(ctx, hit, albedo, rng, throughMedia, shadowRays, atHits);
      IrradianceParts irradiance;
      if (cache.gathers.empty() || !cache.gathers.lookup(px, py, hit, irradiance)) {
        thread_local TraversalScratch scratch;
        const DeltaHitLight::Counts before =
            cache.hitLight ? cache.hitLight->threadCounts() : DeltaHitLight::Counts{};
        irradiance = gatherIrradianceParts(*cache.cloud, hit.point, hit.normal, options, rng,
                                           scratch, &hit.shading);
        if (cache.hitLight) {  // the delta lights' shadow rays at this gather's hits
          const DeltaHitLight::Counts after = cache.hitLight->threadCounts();
          shadowRays += after.shadowRays - before.shadowRays;
          solveCounts.mediumEvals += after.solve.mediumEvals - before.solve.mediumEvals;
        }
        counters.gatherRays.fetch_add(static_cast<uint64_t>(options.samples),
                                      std::memory_order_relaxed);
      }
      if (!edge) emission = m.emission;
      // The environment's light is direct light (the layers), though the gathers found it.
      direct += albedo * irradiance.background * kInvPi;
      indirect = albedo * irradiance.cloud * kInvPi;
      if (layers) fillSurfaceLayers(*layers, hit, albedo);
    } else {
      environment = ctx.lights.environment(ray.dir);
    }
    const RGB behind = emission + direct + indirect + environment;
    const float tEnd = hitSurface ? hit.t : kInf;
    CameraRayParts parts;
    CameraRayParts* const partsOut = layers ? &parts : nullptr;
    RGB l;
    if (cache.lvoxels) {
      // Traced gathers mark the cells near surfaces; camera rays then leave out the light
      // of cells across a surface.
      const PointCloudScatter scatter{cache.cloud->lvoxels().light,
                                      ctx.lights,
                                      volume.media(),
                                      &ctx.tracer,
                                      cameraShadowRays,
                                      &shadowRays};
      l = volume.radianceWith(ray, tEnd, behind, rng.uniform(), scatter, solveCounts, partsOut);
    } else {
      l = volume.radiance(ray, tEnd, behind, rng, solveCounts, partsOut);
    }
    if (layers) fillRadianceLayers(*layers, parts, emission, direct, indirect, environment);
    if (edge) {
      uint64_t rays = 0;
      const EmitterPixels::Seen seen = emitters->seen(
          ctx, s.x, s.y, rng, [&](const Ray& r) { return volume.transmittance(r, solveCounts); },
          throughMedia, atHits, rays, shadowRays);
      counters.emitterRays.fetch_add(rays, std::memory_order_relaxed);
      l += seen.emission + seen.direct;
      if (layers) {
        layers->emission += seen.emission;
        layers->direct += seen.direct;
      }
    }
    counters.shadowRays.fetch_add(shadowRays, std::memory_order_relaxed);
    addSolveCounts(counters, solveCounts);
    return l;
  };
}

}  // namespace lvox
