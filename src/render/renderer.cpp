#include "src/render/renderer.h"

#include <tbb/global_control.h>

#include <memory>

#include "src/core/error.h"
#include "src/render/direct_integrator.h"
#include "src/render/mc_integrator.h"
#include "src/render/pcb_integrator.h"
#include "src/render/volume_transport.h"

namespace lvox {

void validateMode(const Scene& scene) {
  const std::string& mode = scene.render.mode;
  if (mode != "direct" && mode != "mc" && mode != "pcb" && mode != "pcb-surfels")
    throw InputError(scene.path, "render.mode",
                     "unknown mode '" + mode + "' (direct, mc, pcb, pcb-surfels)");
}

Image renderScene(const Scene& scene, Report& report) {
  RenderPlan plan;
  plan.spp = scene.render.spp;
  return renderScene(scene, plan, report).image;
}

RenderResult renderScene(const Scene& scene, const RenderPlan& plan, Report& report) {
  validateMode(scene);
  std::unique_ptr<tbb::global_control> threads;
  if (scene.render.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    static_cast<size_t>(scene.render.threads));
  std::unique_ptr<RayTracer> tracer;
  {
    PhaseTimer timer(report, "bvh_build");
    tracer = std::make_unique<RayTracer>(scene.mesh);
  }
  const LightSet lights(scene, scene.render.areaLightSamples);
  const LightSet singleSampleLights(scene, 1);
  const RenderContext ctx{scene, *tracer, lights};
  MediaSet media;
  {
    PhaseTimer timer(report, "media_load");
    media = MediaSet::build(scene, report.warnings);
  }
  const VolumeTransport volume(ctx, media);
  const RenderContext neeCtx{scene, *tracer, singleSampleLights};
  const MajorantTracker tracker(media, scene.volume.majorantGrid);
  report.memory["media"] = media.memoryBytes();
  SamplerCounters counters;
  PointBasedCache pointCache;
  PixelSampler sampler;
  if (scene.render.mode == "mc") {
    sampler = monteCarloSampler(neeCtx, tracker, counters);
  } else if (scene.render.mode == "pcb" || scene.render.mode == "pcb-surfels") {
    pointCache = buildPointCloud(ctx, volume, report);
    sampler = pcbSampler(ctx, volume, pointCache, plan.spp, counters);
  } else {
    sampler = directSampler(ctx, volume, counters);
  }
  TileStats stats;
  RenderResult result;
  {
    PhaseTimer timer(report, "render");
    result = renderProgressive(scene.camera.width, scene.camera.height, scene.render.seed, sampler,
                               plan, stats);
  }
  report.add("triangles", scene.mesh.triangleCount());
  report.add("camera_rays", stats.samples);
  report.add("invalid_samples", stats.invalidSamples);
  counters.addTo(report);
  report.settings["mode"] = scene.render.mode;
  report.settings["spp"] = std::to_string(result.sppDone);
  report.settings["first_sample"] = std::to_string(plan.firstSample);
  report.settings["seed"] = std::to_string(scene.render.seed);
  report.settings["scene"] = scene.path;
  const double seconds = report.times["render"];
  if (seconds > 0 && counters.paths.load() > 0)
    report.settings["paths_per_second"] =
        std::to_string(static_cast<double>(counters.paths.load()) / seconds);
  return result;
}

}  // namespace lvox
