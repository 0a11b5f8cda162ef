#include "src/render/renderer.h"

#include <tbb/global_control.h>

#include <memory>

#include "src/render/direct_integrator.h"
#include "src/render/mc_integrator.h"
#include "src/render/pcb_integrator.h"
#include "src/render/volume_transport.h"

namespace lvox {

Image renderScene(const RenderJob& job, Report& report) {
  RenderPlan plan;
  plan.spp = job.render.spp;
  return renderScene(job, plan, report).image;
}

RenderResult renderScene(const RenderJob& job, const RenderPlan& plan, Report& report) {
  const World& world = job.world;
  const RenderSettings& settings = job.render;
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
  const RenderContext ctx{world, settings, *tracer, lights};
  MediaSet media;
  {
    PhaseTimer timer(report, "media_load");
    media = MediaSet::build(job.media, job.volume.interpolation, report.warnings);
  }
  const VolumeTransport volume(ctx, media, job.volume);
  const RenderContext neeCtx{world, settings, *tracer, singleSampleLights};
  const MajorantTracker tracker(media, job.volume.majorant == MajorantKind::kGrid);
  report.memory["media"] = media.memoryBytes();
  SamplerCounters counters;
  PointBasedCache pointCache;
  PixelSampler sampler;
  switch (settings.mode) {
    case Mode::kMc:
      sampler = monteCarloSampler(neeCtx, tracker, counters);
      break;
    case Mode::kPcb:
    case Mode::kPcbSurfels:
      pointCache = buildPointCloud(ctx, volume, job.pointcloud, job.sceneFile, report);
      sampler = pcbSampler(ctx, volume, pointCache, job.pointcloud, plan.spp, counters);
      break;
    case Mode::kDirect:
      sampler = directSampler(ctx, volume, counters);
      break;
  }
  TileStats stats;
  RenderResult result;
  {
    PhaseTimer timer(report, "render");
    result = renderProgressive(world.camera.width, world.camera.height, settings.seed, sampler,
                               plan, stats);
  }
  report.add("triangles", world.mesh.triangleCount());
  report.add("camera_rays", stats.samples);
  report.add("invalid_samples", stats.invalidSamples);
  counters.addTo(report);
  report.settings["mode"] = std::string(modeName(settings.mode));
  report.settings["spp"] = std::to_string(result.sppDone);
  report.settings["first_sample"] = std::to_string(plan.firstSample);
  report.settings["seed"] = std::to_string(settings.seed);
  // Every setting that changes the image, by its scene field (lvox merge compares them).
  for (const SettingList& list :
       {describe(job.render), describe(job.volume), describe(job.pointcloud)})
    for (const auto& [field, value] : list.items()) report.settings[field] = value;
  const double seconds = report.times["render"];
  if (seconds > 0 && counters.paths.load() > 0)
    report.settings["paths_per_second"] =
        std::to_string(static_cast<double>(counters.paths.load()) / seconds);
  return result;
}

}  // namespace lvox
