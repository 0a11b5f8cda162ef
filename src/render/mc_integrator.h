#pragma once
// --mode mc: the unbiased reference. A path tracer over Lambertian surfaces with
// next-event estimation to every light, cosine-weighted continuation and Russian
// roulette; `max_bounces` counts scattering events, so 1 is single scattering.
#include "src/render/render_context.h"
#include "src/render/sampler_counters.h"
#include "src/render/tile_renderer.h"

namespace lvox {

// `neeLights` must be the scene's lights with one sample per area light and vertex.
PixelSampler monteCarloSampler(const RenderContext& ctx, const LightSet& neeLights,
                               SamplerCounters& counters);

}  // namespace lvox
