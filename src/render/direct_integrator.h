#pragma once
// --mode direct: light straight from the light sources. Surfaces get direct light with
// exact shadow rays; camera rays that escape see the environment.
#include "src/core/image.h"
#include "src/render/render_context.h"
#include "src/render/report.h"

namespace lvox {

Image renderDirect(const RenderContext& ctx, Report& report);

}  // namespace lvox
