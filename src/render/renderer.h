#pragma once
// Renders a scene in the mode its settings name.
#include "src/render/progressive.h"
#include "src/render/render_job.h"
#include "src/render/report.h"

namespace lvox {

// Renders with the job's spp, all at once.
Image renderScene(const RenderJob& job, Report& report);
// Renders by a plan: sample ranges, a time budget, convergence against a reference.
RenderResult renderScene(const RenderJob& job, const RenderPlan& plan, Report& report);

}  // namespace lvox
