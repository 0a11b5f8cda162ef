#pragma once
// Renders a loaded scene in the mode its settings name.
#include "src/core/image.h"
#include "src/render/report.h"
#include "src/scene/scene.h"

namespace lvox {

// The modes lvox knows; throws InputError naming `render.mode` for any other.
void validateMode(const Scene& scene);

Image renderScene(const Scene& scene, Report& report);

}  // namespace lvox
