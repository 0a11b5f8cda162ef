#pragma once
// The world's sections of a scene file: "camera", "materials", "shapes" (meshes are loaded
// here) and "lights". Format: docs/scene-format.md.
#include <optional>
#include <string>
#include <vector>

#include "src/core/json_fields.h"
#include "src/world/world.h"

namespace lvox {

Camera parseCamera(JsonObject c);
// Appends one material per key of the "materials" object.
void parseMaterials(JsonObject m, World& world);
// Adds one shape's triangles; every file it reads is appended to `inputFiles` (textures
// are in `world.textures`). A glTF's camera goes to `fileCamera` unless one is there.
void parseShape(JsonObject s, World& world, std::vector<std::string>& inputFiles,
                std::optional<Camera>& fileCamera);
Light parseLight(JsonObject l);

}  // namespace lvox
