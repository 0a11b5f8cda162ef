#pragma once
// --mode mc: the unbiased reference. A path tracer over Lambertian surfaces with
// next-event estimation to every light, cosine-weighted continuation and Russian
// roulette; `max_bounces` counts scattering events, so 1 is single scattering.
#include "src/core/image.h"
#include "src/render/render_context.h"
#include "src/render/report.h"

namespace lvox {

Image renderMonteCarlo(const RenderContext& ctx, Report& report);

}  // namespace lvox
