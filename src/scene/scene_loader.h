#pragma once
#include <string>

#include "src/scene/scene.h"

namespace lvox {

// Reads and validates a scene file (format: docs/scene-format.md). Throws InputError
// naming the file and field on any problem; unknown keys are errors, not ignored.
Scene loadScene(const std::string& path);

// Same, from JSON text; `path` is used for messages and to resolve relative file names.
Scene parseScene(const std::string& text, const std::string& path);

}  // namespace lvox
