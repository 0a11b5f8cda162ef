#include "src/render/renderer.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <iterator>
#include <memory>
#include <vector>

#include "src/core/error.h"
#include "src/core/work_budget.h"
#include "src/render/direct_integrator.h"
#include "src/render/distributed_render.h"
#include "src/render/mc_integrator.h"
#include "src/render/pcb_integrator.h"
#include "src/render/volume_transport.h"

namespace lvox {
namespace {

// Monte Carlo samples are independent whatever their number; the pcb sampler's gathers
// per sample depend on the spp, so its pixels are split instead (distributed_render.h).
RenderSplit distributedSplit(Mode mode) {
  return mode == Mode::kMc ? RenderSplit::kSampleRanges : RenderSplit::kTileBands;
}

// Split over ranks, each counted its own share of the image: the report counts the whole.
void sumOverRanks(SamplerCounters& counters, TileStats& stats, Collective& team) {
  std::atomic<uint64_t>* const atomics[] = {&counters.shadowRays,     &counters.pathRays,
                                            &counters.paths,          &counters.gatherRays,
                                            &counters.mediumEvals,    &counters.solverSteps,
                                            &counters.rejectedSteps,  &counters.stabilityEvents,
                                            &counters.cappedSegments, &counters.emitterRays};
  std::vector<uint64_t> values{stats.samples, stats.invalidSamples};
  for (const std::atomic<uint64_t>* a : atomics) values.push_back(a->load());
  team.sum(values);
  stats.samples = values[0];
  stats.invalidSamples = values[1];
  for (size_t i = 0; i < std::size(atomics); ++i) atomics[i]->store(values[i + 2]);
}

// The camera phase against the work budget: every 256th sample projects the phase's
// evaluations from the samples done, and once the budget is exhausted the remaining
// samples return at once (the render then fails with the budget's error).
PixelSampler meteredSampler(PixelSampler sampler, WorkBudget& work,
                            const std::atomic<uint64_t>& evaluations, uint64_t total) {
  auto done = std::make_shared<std::atomic<uint64_t>>(0);
  return [sampler = std::move(sampler), &work, &evaluations, total, done](
             const PixelSample& s, Rng& rng, SampleLayers* layers) -> RGB {
    if (work.exhausted()) return RGB(0.0f);
    const RGB v = sampler(s, rng, layers);
    const uint64_t n = done->fetch_add(1, std::memory_order_relaxed) + 1;
    if (n % 256 == 0)
      work.project(evaluations.load(std::memory_order_relaxed), n, total, "the camera rays");
    return v;
  };
}

}  // namespace

Image renderScene(const RenderJob& job, Report& report) {
  RenderPlan plan;
  plan.spp = job.render.spp;
  return renderScene(job, plan, report).image;
}

namespace {

// The plan with the scene's adaptive samples, which need every first sample of the image
// in one pass before the extra ones: given in the scene, a plan that cannot have them is an
// error; under "auto" such a plan renders even samples, and the report says so.
RenderPlan withAdaptiveSamples(RenderPlan plan, const RenderJob& job, Report& report) {
  RenderSettings settings = job.render;
  settings.spp = plan.spp;
  plan.adaptiveSpp = adaptiveSamplesFor(settings);
  if (plan.adaptiveSpp == 0) return plan;
  const bool automatic = job.render.adaptiveSpp == RenderSettings::kAutoAdaptive;
  const char* field = "render.adaptive_spp";
  const char* why =
      plan.timeLimitSeconds > 0.0 ? "needs no --time-limit"
      : plan.reference            ? "needs no --convergence"
      : plan.firstSample != 0
          ? "needs --first-sample 0: a chunk's extra samples would be the next chunk's"
          : nullptr;
  if (!why && plan.adaptiveSpp <= plan.spp) why = "must be more than the samples per pixel (--spp)";
  if (!why) return plan;
  if (!automatic) throw InputError(job.sceneFile, field, why);
  report.warnings.push_back(std::string("adaptive samples are off: ") + field + " " + why);
  plan.adaptiveSpp = 0;
  return plan;
}

}  // namespace

RenderResult renderScene(const RenderJob& job, const RenderPlan& requested, Report& report) {
  const World& world = job.world;
  const RenderSettings& settings = job.render;
  const RenderPlan plan = withAdaptiveSamples(requested, job, report);
  Collective& team = plan.team ? *plan.team : singleProcess();
  std::unique_ptr<tbb::global_control> threads;
  if (settings.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    static_cast<size_t>(settings.threads));
  // One texture system per render, shared by every thread (none without textures).
  const SurfaceTextures textures(world);
  std::unique_ptr<RayTracer> tracer;
  {
    PhaseTimer timer(report, "bvh_build");
    tracer = std::make_unique<RayTracer>(world.mesh, textures.empty() ? nullptr : &textures);
  }
  const LightSet lights(world, settings.areaLightSamples);
  const LightSet singleSampleLights(world, 1);
  MemoryBudget budget(settings.maxMemory);
  const uint64_t cameraSamples = static_cast<uint64_t>(world.camera.width) * world.camera.height *
                                 static_cast<uint64_t>(std::max(plan.spp, plan.adaptiveSpp));
  WorkBudget work(settings.maxEvaluations, cameraSamples, job.sceneFile);
  // The accumulation buffers and the output image (the progressive renderer's sums,
  // variance and counts): about 64 bytes per pixel.
  const uint64_t pixels = static_cast<uint64_t>(world.camera.width) * world.camera.height;
  budget.reserve(pixels * 64, job.sceneFile, "camera.width", "the image");
  if (plan.adaptiveSpp > 0)  // the first samples' moments (PixelMoments) and the counts
    budget.reserve(pixels * (2 * sizeof(double) + sizeof(uint64_t) + sizeof(uint32_t)),
                   job.sceneFile, "render.adaptive_spp", "the adaptive samples' moments");
  if (!plan.layers.empty())
    budget.reserve(pixels * Film::layerBytesPerPixel(plan.layers), job.sceneFile, "--layers",
                   "the layers' sums");
  const RenderContext ctx{world, settings, *tracer, lights, &budget};
  MediaSet media;
  const uint64_t reservedBeforeMedia = budget.reserved();
  {
    PhaseTimer timer(report, "media_load");
    media = MediaSet::build(job.media, job.volume.interpolation, report.warnings, &budget);
  }
  VolumeTransport volume(ctx, media, job.volume);
  if (settings.mode == Mode::kDirect && job.volume.shadowCache > 0 && media.anyHeterogeneous()) {
    PhaseTimer timer(report, "shadow_cache");
    // At most (resolution + 2)^3 nodes of one RGB per light, checked before building.
    const uint64_t side = static_cast<uint64_t>(job.volume.shadowCache) + 2;
    budget.reserve(side * side * side * sizeof(RGB) * world.lights.size(), job.sceneFile,
                   "volume_integrator.shadow_cache", "the shadow transmittance cache");
    const uint64_t cameraRays =
        static_cast<uint64_t>(world.camera.width) * world.camera.height * plan.spp;
    const uint64_t cacheEvals = volume.buildShadowCache(job.volume.shadowCache, cameraRays);
    report.add("shadow_cache_medium_evals", cacheEvals);
    work.charge(cacheEvals, "the shadow transmittance cache");
    work.throwIfExhausted();
    if (volume.shadowCache()) report.memory["shadow_cache"] = volume.shadowCache()->memoryBytes();
  }
  if (settings.mode == Mode::kDirect && job.volume.environmentCache > 0 &&
      media.anyHeterogeneous()) {
    PhaseTimer timer(report, "environment_cache");
    const uint64_t side = static_cast<uint64_t>(job.volume.environmentCache) + 2;
    // The harmonics and a near-surface mark per node.
    budget.reserve(side * side * side * (sizeof(RGB) * kShCoefficients + 1), job.sceneFile,
                   "volume_integrator.environment_cache", "the environment's light cache");
    const uint64_t cameraRays =
        static_cast<uint64_t>(world.camera.width) * world.camera.height * plan.spp;
    const uint64_t cacheEvals = volume.buildEnvironmentCache(
        job.volume.environmentCache, job.volume.environmentDirections, cameraRays);
    report.add("environment_cache_medium_evals", cacheEvals);
    work.charge(cacheEvals, "the environment's light cache");
    work.throwIfExhausted();
    if (volume.environmentCache()) {
      report.memory["environment_cache"] = volume.environmentCache()->memoryBytes();
      report.add("environment_cache_nodes_near_surfaces",
                 volume.environmentCache()->nodesNearSurfaces());
    }
  }
  const RenderContext neeCtx{world, settings, *tracer, singleSampleLights, &budget};
  const MajorantTracker tracker(media, job.volume.majorant == MajorantKind::kGrid);
  report.memory["media"] = media.memoryBytes();
  // The grids' trees were reserved as they were read; the rest (majorants) now.
  const uint64_t gridsReserved = budget.reserved() - reservedBeforeMedia;
  if (media.memoryBytes() > gridsReserved)
    budget.reserve(media.memoryBytes() - gridsReserved, job.sceneFile, "media",
                   "the media's grids");
  SamplerCounters counters;
  PointBasedCache pointCache;
  PixelSampler sampler;
  switch (settings.mode) {
    case Mode::kMc:
      sampler = monteCarloSampler(neeCtx, tracker, counters);
      break;
    case Mode::kPcb:
    case Mode::kPcbSurfels:
      pointCache = buildPointCloud(ctx, volume, job.pointcloud, job.sceneFile, report, team);
      // The caches' own evaluations and those of the delta lights' shadow rays at the
      // interreflection's and the screen grid's gather hits.
      work.charge(report.count("cache_medium_evals") + report.count("gather_hit_medium_evals"),
                  "the point cloud's light cache");
      work.throwIfExhausted();
      if (plan.cloudOut) *plan.cloudOut = exportCloud(*pointCache.cloud, pointCache.hitLight.get());
      sampler = pcbSampler(ctx, volume, pointCache, job.pointcloud, plan.spp, counters);
      break;
    case Mode::kDirect:
      sampler = directSampler(ctx, volume, counters);
      break;
  }
  sampler = meteredSampler(std::move(sampler), work, counters.mediumEvals,
                           cameraSamples / static_cast<uint64_t>(team.size()));
  TileStats stats;
  RenderResult result;
  {
    PhaseTimer timer(report, "render");
    if (team.distributed())
      result = renderDistributed(world.camera.width, world.camera.height, settings.seed, sampler,
                                 plan, distributedSplit(settings.mode), team, stats, report);
    else
      result = renderProgressive(world.camera.width, world.camera.height, settings.seed, sampler,
                                 plan, stats);
  }
  work.throwIfExhausted();
  if (team.distributed()) sumOverRanks(counters, stats, team);
  report.add("triangles", world.mesh.triangleCount());
  report.memory["budget"] = budget.limit();
  report.add("evaluation_budget", work.limit());
  report.memory["budget_reserved"] = budget.reserved();
  report.add("camera_rays", stats.samples);
  report.add("adaptive_samples", result.extraSamples);
  report.add("invalid_samples", stats.invalidSamples);
  counters.addTo(report);
  report.settings["mode"] = std::string(modeName(settings.mode));
  report.settings["spp"] = std::to_string(result.sppDone);
  report.settings["first_sample"] = std::to_string(plan.firstSample);
  report.settings["seed"] = std::to_string(settings.seed);
  if (team.distributed()) report.settings["ranks"] = std::to_string(team.size());
  if (!plan.layers.empty()) report.settings["layers"] = plan.layers.toString();
  // Every setting that changes the image, by its scene field (lvox merge compares them).
  // The point cloud's change only the pcb modes' images: an MC reference keeps merging
  // across a change of the cloud's defaults.
  std::vector<SettingList> lists{describe(job.render), describe(job.volume)};
  if (isPointBased(settings.mode)) lists.push_back(describe(job.pointcloud));
  for (const SettingList& list : lists)
    for (const auto& [field, value] : list.items()) report.settings[field] = value;
  // The samples the render took, "auto" resolved: a chunk with adaptive samples and one
  // without (--first-sample other than 0) are not chunks of one image, and lvox merge says so.
  report.settings["render.adaptive_spp"] = std::to_string(plan.adaptiveSpp);
  const double seconds = report.times["render"];
  if (seconds > 0 && counters.paths.load() > 0)
    report.settings["paths_per_second"] =
        std::to_string(static_cast<double>(counters.paths.load()) / seconds);
  return result;
}

}  // namespace lvox
