#pragma once
// Direct light reflected by a Lambertian surface point: every light, exact shadow rays.
#include "src/render/render_context.h"

namespace lvox {

// Which lights a direct-light estimate sums (all by default). pcb with traced gathers
// leaves the point, spot and directional lights of its surfels to the gathers' hits
// (delta_hit_light.h), and the constant environment of its surfels and camera hits to
// the gathers' escaping rays (docs/pcb.md).
struct LightSubset {
  bool delta = true;                // point, spot and directional lights
  bool area = true;                 // the environment and the emissive triangles
  bool constantEnvironment = true;  // with `area`: the uniform sky among them
};

// Reflected radiance rho/pi * sum_lights Li cos(theta) V, theta from the shading normal.
// `transmittance(ray)` gives the fraction of light that survives the media along an unoccluded
// shadow ray (1 without media); it is only called for rays that no surface blocks.
template <class Transmittance>
RGB surfaceDirect(const RenderContext& ctx, const SurfaceHit& hit, const RGB& albedo, Rng& rng,
                  Transmittance&& transmittance, uint64_t& shadowRays, LightSubset subset = {}) {
  RGB sum(0.0f);
  auto add = [&](const LightSample& s) {
    // The geometric normal decides visibility, the shading normal the cosine.
    if (dot(s.wi, hit.normal) <= 0.0f) return;
    const float cosTheta = dot(s.wi, hit.shading);
    if (cosTheta <= 0.0f) return;
    const Ray shadow = ctx.spawn(hit.point, hit.normal, s.wi, s.distance);
    ++shadowRays;
    if (ctx.tracer.occluded(shadow)) return;
    sum += s.radiance * transmittance(shadow) * cosTheta;
  };
  // Delta lights first, as LightSet::forEachSample: the same sums in the same order.
  if (subset.delta) ctx.lights.forEachDeltaSample(hit.point, add);
  if (subset.area)
    ctx.lights.forEachAreaSample(hit.point, &hit.normal, rng, add, subset.constantEnvironment);
  return albedo * sum * kInvPi;
}

}  // namespace lvox
