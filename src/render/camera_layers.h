#pragma once
// How the direct and pcb samplers fill a sample's layers (layers.h) from what their camera
// ray met: the first surface's guide values, and the radiance parts behind the media seen
// through the camera ray's transmittance.
#include "src/geometry/ray_tracer.h"
#include "src/render/layers.h"
#include "src/render/volume_transport.h"

namespace lvox {

inline void fillSurfaceLayers(SampleLayers& layers, const SurfaceHit& hit, const RGB& albedo) {
  layers.hit = true;
  layers.depth = hit.t;
  layers.normal = hit.shading;
  layers.albedo = albedo;
}

// `emission`, `direct`, `indirect` leave the first surface (or `environment` arrives from
// behind when there is none); `parts` is what the media along the camera ray add.
inline void fillRadianceLayers(SampleLayers& layers, const CameraRayParts& parts,
                               const RGB& emission, const RGB& direct, const RGB& indirect,
                               const RGB& environment) {
  const RGB& t = parts.transmittance;
  layers.emission = t * emission + parts.emission;
  layers.direct = t * direct;
  layers.indirect = t * indirect;
  layers.environment = t * environment;
  layers.volume = parts.inScatter;
}

}  // namespace lvox
