#pragma once
// The two ways of turning the scene's triangles into surfels (phase 1).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pointcloud/surfels.h"
#include "src/geometry/ray_tracer.h"
#include "src/world/world.h"

namespace lvox {

// View-independent: about area / spacing^2 surfels spread uniformly over all triangles.
// Triangles holding >= kLatticeMinSurfels expected surfels get the points of a hexagonal
// lattice in their plane (randomly offset by the seed, shared by coplanar triangles so a
// quad split in two has no seam); smaller triangles get floor or ceil of their expected
// count by systematic rounding of the running sum, stratified inside the triangle.
struct UniformSurfelSettings {
  float spacing = 0.0f;  // scene units, > 0
  // Disk radius = spacing / sqrt(pi) * radiusScale. 1.15 makes the disks of a hexagonal
  // lattice cover the plane (covering radius 0.6204 * spacing < 0.6488 * spacing).
  float radiusScale = 1.15f;
  uint64_t seed = 1;
  // Only the triangles [firstTriangle, endTriangle) (clamped to the mesh): exactly the
  // surfels, in the same order, that sampling the whole mesh puts on them, so slices
  // sampled apart (one per rank) and concatenated in triangle order are the whole set.
  size_t firstTriangle = 0;
  size_t endTriangle = SIZE_MAX;
};
inline constexpr float kLatticeMinSurfels = 4.0f;

// With `textures`, surfels take the albedo their disk averages and none stands on a
// cut-away texel.
SurfelSet sampleSurfelsUniform(const TriangleMesh& mesh, const std::vector<Material>& materials,
                               const UniformSurfelSettings& settings,
                               const SurfaceTextures* textures = nullptr);

// Camera-based (Gibson 2011): one surfel per hit of a jittered ray grid through a frustum
// `margin` wider than the view (each side grows by margin/2), at `rate` rays per pixel
// side. The radius comes from the ray's footprint on the surface at the hit distance.
struct CameraSurfelSettings {
  float margin = 0.1f;
  float rate = 2.0f;
  float radiusScale = 1.15f;
  float minCosine = 0.1f;  // grazing hits: footprint area capped at 1/minCosine
  uint64_t seed = 1;
};

SurfelSet sampleSurfelsFromCamera(const RayTracer& tracer, const std::vector<Material>& materials,
                                  const Camera& camera, const CameraSurfelSettings& settings);

}  // namespace lvox
