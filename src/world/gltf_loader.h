#pragma once
// Loads glTF 2.0 files (.gltf with external buffers and images, or .glb) through assimp.
#include <optional>
#include <string>

#include "src/world/mesh_loader.h"

namespace lvox {

// Appends every mesh the glTF's node hierarchy places (node transforms, then `xf`), with
// one world material per glTF material named "<file stem>/<material>": base-colour factor
// times base-colour texture (relative to the glTF's folder), emissive factor times
// strength. The first camera, if the file has one, goes to `camera` (its aspect sets the
// image height for a 512-pixel width).
MeshLoadStats loadGltf(const std::string& path, const std::string& field, const Transform& xf,
                       World& world, std::optional<Camera>& camera);

}  // namespace lvox
