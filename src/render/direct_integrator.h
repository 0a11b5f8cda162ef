#pragma once
// --mode direct: light straight from the light sources. Surfaces get direct light with
// exact shadow rays; camera rays that escape see the environment.
#include "src/render/render_context.h"
#include "src/render/sampler_counters.h"
#include "src/render/tile_renderer.h"

namespace lvox {

PixelSampler directSampler(const RenderContext& ctx, SamplerCounters& counters);

}  // namespace lvox
