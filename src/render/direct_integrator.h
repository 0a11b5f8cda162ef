#pragma once
// --mode direct: light straight from the light sources. Surfaces get direct light with
// exact shadow rays (attenuated by the media they cross); camera rays through media get
// emission and single scattering from the RTE solver; escaping rays see the environment.
#include "src/render/render_context.h"
#include "src/render/sampler_counters.h"
#include "src/render/tile_renderer.h"
#include "src/render/volume_transport.h"

namespace lvox {

PixelSampler directSampler(const RenderContext& ctx, const VolumeTransport& volume,
                           SamplerCounters& counters);

// Adds one solve's counts to the shared counters.
void addSolveCounts(SamplerCounters& counters, const rte::SolveCounts& c);

}  // namespace lvox
