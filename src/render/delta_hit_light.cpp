#include "src/render/delta_hit_light.h"

#include "pointcloud/cube_transmittance.h"
#include "src/render/surface_albedo.h"
#include "src/render/surface_direct.h"

namespace lvox {

RGB DeltaHitLight::reflected(const SurfaceHit& hit) const {
  const RGB white = reflectedAt(hit, RGB(1.0f));
  if (isBlack(white)) return white;  // most hits: the texture lookup is then saved
  const World& world = ctx_.world;
  const Material& m = world.materials[world.mesh.triangleMaterial[hit.triangle]];
  // A point lookup, as MC's path vertices: the gathers through a pixel average it.
  return white * hitAlbedo(ctx_, m, hit);
}

RGB DeltaHitLight::reflected(const Vec3& p, const Vec3& n, const RGB& albedo) const {
  SurfaceHit hit;
  hit.point = p;
  hit.normal = n;
  hit.shading = n;
  return reflectedAt(hit, albedo);
}

RGB DeltaHitLight::reflectedAt(const SurfaceHit& hit, const RGB& albedo) const {
  Counts& local = counts_.local();
  auto throughMedia = [&](const Ray& shadow) {
    if (cubes_) {
      thread_local TraversalScratch scratch;
      return cubeTransmittance(*cubes_, shadow, scratch);
    }
    return volume_.transmittance(shadow, local.solve, reducedShadows_);
  };
  Rng unused(0, 0);  // delta lights take no random numbers
  const RGB l = surfaceDirect(ctx_, hit, albedo, unused, throughMedia, local.shadowRays,
                              LightSubset{.area = false});
  return isFinite(l) ? l : RGB(0.0f);
}

DeltaHitLight::Counts DeltaHitLight::total() const {
  Counts sum;
  counts_.combine_each([&](const Counts& c) {
    sum.shadowRays += c.shadowRays;
    sum.solve += c.solve;
  });
  return sum;
}

}  // namespace lvox
