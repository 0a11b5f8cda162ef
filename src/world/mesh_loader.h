#pragma once
// Loads triangle meshes (OBJ with MTL colours, PLY) into the world's mesh.
#include <optional>
#include <string>
#include <vector>

#include "src/world/world.h"

namespace lvox {

struct MeshLoadStats {
  size_t triangles = 0;
  size_t skippedDegenerate = 0;  // zero-area or non-finite triangles, not added
};

// Appends the OBJ's triangles, transformed, to `world.mesh`. Each MTL material becomes a
// world material named "<file stem>/<mtl name>" with albedo Kd (and emission Ke), unless
// `materialOverride` is the index of a material to use for every triangle.
MeshLoadStats loadObj(const std::string& path, const std::string& field, const Transform& xf,
                      std::optional<uint32_t> materialOverride, World& world);

// The material libraries an OBJ names (its `mtllib` lines), resolved against its folder:
// files the render reads, which no output may replace.
std::vector<std::string> objMaterialLibraries(const std::string& path);

// Appends the PLY's triangles (polygons are triangulated), all with `material`.
MeshLoadStats loadPly(const std::string& path, const std::string& field, const Transform& xf,
                      uint32_t material, World& world);

// Adds one triangle unless it is degenerate or non-finite; returns whether it was added.
bool addTriangle(TriangleMesh& mesh, const Vec3& a, const Vec3& b, const Vec3& c, uint32_t material,
                 const TriangleAttributes& attributes = {});

}  // namespace lvox
