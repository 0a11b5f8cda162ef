// Where the point cloud's one-bounce irradiance goes wrong, ray by ray (docs/results.md,
// "What the darkness is made of"). At camera hits on a grid of pixels, every gather ray
// is traced twice: through the cloud (the first surfel disk, Gibson) and through the
// real geometry, whose hit gets the exact direct light (sun, sky, area lights; media are
// ignored: use a scene without them). Rays are classed by what the cloud hit against
// what the geometry hit, and the light of each class is summed both ways.
//
//   build/tests/bench/lvox_visibility_study SCENE.json SURFELS [OFFSET_IN_SPACINGS]
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "pointcloud/buried_surfels.h"
#include "pointcloud/gather.h"
#include "pointcloud/light_cache.h"
#include "pointcloud/surfel_sampler.h"
#include "src/render/light_set.h"
#include "src/render/render_context.h"
#include "src/render/surface_direct.h"
#include "src/scene/scene_loader.h"

namespace lvox {
namespace {

struct FirstDisk {
  float t = -1.0f;
  uint32_t index = 0;
  bool front = false;
  void surfel(uint32_t i, float hitT, bool f) {
    t = hitT;
    index = i;
    front = f;
  }
  bool lvoxel(uint32_t, float, float) { return true; }
  bool surfelCluster(uint32_t, float, float) { return true; }
  bool lvoxelCluster(uint32_t, float, float) { return true; }
};

enum RayClass { kMiss, kNearer, kFarther, kSame, kClasses };
const char* const kClassNames[kClasses] = {"cloud finds no disk", "cloud stops nearer",
                                           "cloud passes the surface", "same surface"};

int run(const char* scenePath, int targetSurfels, float offset) {
  const Scene scene = loadScene(scenePath);
  const float spacing = static_cast<float>(std::sqrt(scene.world.mesh.area() / targetSurfels));
  const RayTracer tracer(scene.world.mesh);
  const LightSet lights(scene.world, scene.render.areaLightSamples);
  const RenderContext ctx{scene.world, scene.render, tracer, lights};
  SurfelSet surfels =
      sampleSurfelsUniform(scene.world.mesh, scene.world.materials, {spacing, 1.15f, 1});
  removeBuriedSurfels(surfels, tracer, {4.0f * spacing, 16, 1, scene.world.camera.position});
  PointCloud cloud(std::move(surfels), LvoxelSet{});
  auto unattenuated = [](const Ray&) { return RGB(1.0f); };
  cacheDirectLight(
      cloud,
      [&](const SurfelLightQuery& q) {
        SurfaceHit at;
        at.point = q.position;
        at.normal = q.normal;
        Rng rng(7, q.index);
        uint64_t rays = 0;
        return surfaceDirect(ctx, at, q.albedo, rng, unattenuated, rays);
      },
      [](const LvoxelLightQuery&) { return RGB(0.0f); });
  const CloudSurfels& s = cloud.surfels();

  double count[kClasses] = {}, cloudLight[kClasses] = {}, trueLight[kClasses] = {};
  double passedThrough[3] = {};
  const int rows = 16, cols = 16;
  TraversalScratch scratch;
  for (int py = 8; py < scene.world.camera.height; py += 16)
    for (int px = 8; px < scene.world.camera.width; px += 16) {
      SurfaceHit hit;
      const Ray cameraRay = scene.world.camera.generateRay(static_cast<float>(px) + 0.5f,
                                                           static_cast<float>(py) + 0.5f);
      if (!tracer.intersect(cameraRay, hit)) continue;
      const Frame frame(hit.normal);
      Rng rng(1, static_cast<uint64_t>(py) * 100000 + px);
      for (int a = 0; a < rows; ++a)
        for (int b = 0; b < cols; ++b) {
          const float u1 = (static_cast<float>(a) + rng.uniform()) / static_cast<float>(rows);
          const float u2 = (static_cast<float>(b) + rng.uniform()) / static_cast<float>(cols);
          const Vec3 dir = frame.toWorld(cosineHemisphere(u1, u2));
          SurfaceHit real;
          if (!tracer.intersect(ctx.spawn(hit.point, hit.normal, dir), real)) continue;
          uint64_t rays = 0;
          const Material& m =
              scene.world.materials[scene.world.mesh.triangleMaterial[real.triangle]];
          const RGB exact = surfaceDirect(ctx, real, m.albedo, rng, unattenuated, rays);
          FirstDisk disk;
          traverse(cloud, Ray{hit.point, dir, offset * spacing, kInf}, disk, TraversalOptions{},
                   scratch);
          const RGB seen = disk.t < 0.0f ? RGB(0.0f)
                                         : (disk.front ? s.radianceFront[disk.index]
                                                       : s.radianceBack[disk.index]);
          const RayClass c = disk.t < 0.0f                      ? kMiss
                             : disk.t < real.t - 2.0f * spacing ? kNearer
                             : disk.t > real.t + 2.0f * spacing ? kFarther
                                                                : kSame;
          if (c == kFarther) {
            // Through what: a surface within the ray offset, a small triangle (random
            // surfels), or a lattice triangle.
            const Vec3 v0 = scene.world.mesh.vertex(real.triangle, 0);
            const float triArea =
                0.5f * length(cross(scene.world.mesh.vertex(real.triangle, 1) - v0,
                                    scene.world.mesh.vertex(real.triangle, 2) - v0));
            const int through = real.t < offset * spacing                          ? 0
                                : triArea < kLatticeMinSurfels * spacing * spacing ? 1
                                                                                   : 2;
            passedThrough[through] += exact.x + exact.y + exact.z;
          }
          count[c] += 1.0;
          cloudLight[c] += seen.x + seen.y + seen.z;
          trueLight[c] += exact.x + exact.y + exact.z;
        }
    }
  double total = 0.0, cloudTotal = 0.0;
  for (int c = 0; c < kClasses; ++c) {
    total += trueLight[c];
    cloudTotal += cloudLight[c];
  }
  std::printf("%zu surfels at spacing %.4f, ray offset %.2f spacings\n", s.size(), spacing, offset);
  for (int c = 0; c < kClasses; ++c)
    std::printf("%-26s %8.0f rays  light lost %6.2f %%\n", kClassNames[c], count[c],
                100.0 * (trueLight[c] - cloudLight[c]) / total);
  const double passed = passedThrough[0] + passedThrough[1] + passedThrough[2];
  std::printf(
      "light of the passed surfaces: %.0f %% within the ray offset, %.0f %% on small "
      "triangles, %.0f %% on lattice triangles\n",
      100.0 * passedThrough[0] / passed, 100.0 * passedThrough[1] / passed,
      100.0 * passedThrough[2] / passed);
  std::printf("cloud / traced one-bounce irradiance: %.4f\n", cloudTotal / total);
  return 0;
}

}  // namespace
}  // namespace lvox

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s SCENE.json SURFELS [OFFSET_IN_SPACINGS]\n", argv[0]);
    return 2;
  }
  try {
    return lvox::run(argv[1], std::atoi(argv[2]), argc > 3 ? std::strtof(argv[3], nullptr) : 0.25f);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lvox_visibility_study: %s\n", e.what());
    return 1;
  }
}
