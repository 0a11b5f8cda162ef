#pragma once
// The albedo of a surface point: the material's constant, or its albedo map looked up over
// the footprint the point stands for. Untextured materials cost one comparison.
#include "src/render/render_context.h"
#include "src/world/surface_textures.h"

namespace lvox {

// A camera ray's pixel footprint on the hit's plane: where the rays through the next pixel
// to the right and below meet that plane (pinhole ray differentials), relative to the hit.
inline void cameraFootprint(const Camera& camera, const Ray& ray, const SurfaceHit& hit, Vec3& dpdx,
                            Vec3& dpdy) {
  const Vec3 forward = normalize(camera.lookAt - camera.position);
  const Vec3 right = normalize(cross(forward, camera.up));
  const Vec3 trueUp = cross(right, forward);
  const float pixel =
      2.0f * std::tan(0.5f * camera.vfovDeg * kPi / 180.0f) / static_cast<float>(camera.height);
  const Vec3 d = ray.dir / dot(ray.dir, forward);  // on the image plane at distance 1
  auto onPlane = [&](const Vec3& dir) {
    const float den = dot(dir, hit.normal);
    if (std::abs(den) < 1e-12f) return Vec3(0.0f);
    return dir * (dot(hit.point - ray.origin, hit.normal) / den) + ray.origin - hit.point;
  };
  dpdx = onPlane(d + right * pixel);
  dpdy = onPlane(d - trueUp * pixel);
}

// Albedo where a camera ray hits: filtered over the pixel's footprint.
inline RGB cameraHitAlbedo(const RenderContext& ctx, const Material& m, const Ray& ray,
                           const SurfaceHit& hit) {
  if (m.albedoMap < 0 || !ctx.tracer.textures()) return m.albedo;
  Vec3 dpdx, dpdy;
  cameraFootprint(ctx.world.camera, ray, hit, dpdx, dpdy);
  return ctx.tracer.textures()->albedo(hit.triangle, hit.b1, hit.b2, dpdx, dpdy);
}

// Albedo where a path vertex lies: a point lookup (the paths through a pixel average it).
inline RGB hitAlbedo(const RenderContext& ctx, const Material& m, const SurfaceHit& hit) {
  return albedoAt(ctx.tracer.textures(), m, hit.triangle, hit.b1, hit.b2);
}

}  // namespace lvox
