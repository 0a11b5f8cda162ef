#pragma once
// Renders a loaded scene in the mode its settings name.
#include "src/render/progressive.h"
#include "src/render/report.h"
#include "src/scene/scene.h"

namespace lvox {

// The modes lvox knows; throws InputError naming `render.mode` for any other.
void validateMode(const Scene& scene);

// Renders with the scene's spp, all at once.
Image renderScene(const Scene& scene, Report& report);
// Renders by a plan: sample ranges, a time budget, convergence against a reference.
RenderResult renderScene(const Scene& scene, const RenderPlan& plan, Report& report);

}  // namespace lvox
