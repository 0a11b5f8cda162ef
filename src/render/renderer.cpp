#include "src/render/renderer.h"

#include <tbb/global_control.h>

#include <memory>

#include "src/core/error.h"
#include "src/render/direct_integrator.h"
#include "src/render/mc_integrator.h"

namespace lvox {

void validateMode(const Scene& scene) {
  const std::string& mode = scene.render.mode;
  if (mode != "direct" && mode != "mc")
    throw InputError(scene.path, "render.mode", "unknown mode '" + mode + "' (direct, mc)");
}

Image renderScene(const Scene& scene, Report& report) {
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
  const RenderContext ctx{scene, *tracer, lights};
  report.add("triangles", scene.mesh.triangleCount());
  report.settings["mode"] = scene.render.mode;
  report.settings["spp"] = std::to_string(scene.render.spp);
  report.settings["seed"] = std::to_string(scene.render.seed);
  if (scene.render.mode == "mc") return renderMonteCarlo(ctx, report);
  return renderDirect(ctx, report);
}

}  // namespace lvox
