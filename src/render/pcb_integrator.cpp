#include "src/render/pcb_integrator.h"

#include <cmath>

#include "pointcloud/gather.h"
#include "pointcloud/light_cache.h"
#include "pointcloud/surfel_sampler.h"
#include "src/render/surface_direct.h"

namespace lvox {
namespace {

float totalArea(const TriangleMesh& mesh) {
  double area = 0.0;
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    const Vec3 a = mesh.vertex(t, 0);
    area += 0.5 * length(cross(mesh.vertex(t, 1) - a, mesh.vertex(t, 2) - a));
  }
  return static_cast<float>(area);
}

float surfelSpacing(const Scene& scene) {
  if (scene.pointcloud.surfelSpacing > 0.0f) return scene.pointcloud.surfelSpacing;
  return std::sqrt(totalArea(scene.mesh) / static_cast<float>(scene.pointcloud.targetSurfels));
}

GatherOptions gatherOptions(const Scene& scene, float spacing, int samples) {
  GatherOptions o;
  o.samples = samples;
  o.maxSolidAngle = scene.pointcloud.clusterSolidAngle;
  // Gather rays start half a spacing out, past the receiver's own (possibly tilted) disks.
  o.rayOffset = 0.5f * spacing;
  o.background = RGB(0.0f);
  return o;
}

}  // namespace

std::unique_ptr<PointCloud> buildPointCloud(const RenderContext& ctx, Report& report) {
  const Scene& scene = ctx.scene;
  const float spacing = surfelSpacing(scene);
  SurfelSet surfels;
  {
    PhaseTimer timer(report, "surfel_sampling");
    if (scene.pointcloud.surfelSampler == "camera") {
      surfels =
          sampleSurfelsFromCamera(ctx.tracer, scene.materials, scene.camera,
                                  CameraSurfelSettings{0.1f, 2.0f, 1.15f, 0.1f, scene.render.seed});
    } else {
      UniformSurfelSettings settings;
      settings.spacing = spacing;
      settings.seed = scene.render.seed;
      surfels = sampleSurfelsUniform(scene.mesh, scene.materials, settings);
    }
  }
  std::unique_ptr<PointCloud> cloud;
  {
    PhaseTimer timer(report, "octree_build");
    cloud = std::make_unique<PointCloud>(std::move(surfels), LvoxelSet{});
  }
  {
    PhaseTimer timer(report, "direct_cache");
    auto noMedia = [](const Ray&) { return RGB(1.0f); };
    cacheDirectLight(
        *cloud,
        [&](const SurfelLightQuery& q) {
          SurfaceHit hit;
          hit.point = q.position;
          hit.normal = q.normal;
          Rng rng(scene.render.seed ^ 0x5eedu,
                  (static_cast<uint64_t>(q.index) << 1) |
                      (dot(q.normal, cloud->surfels().normal[q.index]) < 0));
          uint64_t rays = 0;
          const Material& m = scene.materials[scene.mesh.triangleMaterial[q.triangle]];
          return m.emission + surfaceDirect(ctx, hit, q.albedo, rng, noMedia, rays);
        },
        [](const LvoxelLightQuery&) { return RGB(0.0f); });
  }
  const PointCloudMemory mem = cloud->memory();
  report.add("surfels", cloud->surfels().size());
  report.add("lvoxels", cloud->lvoxels().size());
  report.add("octree_nodes", cloud->nodes().size());
  report.memory["point_cloud"] = mem.surfelBytes + mem.lvoxelBytes;
  report.memory["octree"] = mem.octreeBytes;
  report.memory["bytes_per_surfel"] = SurfelSet::bytesPerElement();
  report.settings["surfel_spacing"] = std::to_string(spacing);
  return cloud;
}

PixelSampler pcbSampler(const RenderContext& ctx, const PointCloud& cloud, int spp,
                        SamplerCounters& counters) {
  const Scene& scene = ctx.scene;
  const int perSample = std::max(1, scene.pointcloud.gatherSamples / std::max(1, spp));
  const GatherOptions options = gatherOptions(scene, surfelSpacing(scene), perSample);
  return [&ctx, &cloud, &counters, options](int x, int y, Rng& rng) {
    const Scene& sc = ctx.scene;
    const Ray ray = sc.camera.generateRay(static_cast<float>(x) + rng.uniform(),
                                          static_cast<float>(y) + rng.uniform());
    SurfaceHit hit;
    if (!ctx.tracer.intersect(ray, hit)) return ctx.lights.environment();
    const Material& m = sc.materials[sc.mesh.triangleMaterial[hit.triangle]];
    uint64_t shadowRays = 0;
    auto noMedia = [](const Ray&) { return RGB(1.0f); };
    const RGB direct = surfaceDirect(ctx, hit, m.albedo, rng, noMedia, shadowRays);
    thread_local TraversalScratch scratch;
    const RGB irradiance = gatherIrradiance(cloud, hit.point, hit.normal, options, rng, scratch);
    counters.shadowRays.fetch_add(shadowRays, std::memory_order_relaxed);
    counters.gatherRays.fetch_add(static_cast<uint64_t>(options.samples),
                                  std::memory_order_relaxed);
    return m.emission + direct + m.albedo * irradiance * kInvPi;
  };
}

}  // namespace lvox
