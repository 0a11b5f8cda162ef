#pragma once
// --mode mc: the unbiased reference. A path tracer over Lambertian surfaces with
// next-event estimation to every light, cosine-weighted continuation and Russian
// roulette; `max_bounces` counts scattering events, so 1 is single scattering.
#include "src/render/render_context.h"
#include "src/render/sampler_counters.h"
#include "src/render/tile_renderer.h"
#include "volume/media/majorant_tracker.h"

namespace lvox {

// `neeCtx` must hold the scene's lights with one sample per area light and vertex (the
// paths do the averaging); `tracker` walks the media.
PixelSampler monteCarloSampler(const RenderContext& neeCtx, const MajorantTracker& tracker,
                               SamplerCounters& counters);

}  // namespace lvox
