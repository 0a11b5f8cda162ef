#pragma once
// Participating media in pcb mode (Gibson 2011, extended with the RTE solvers).
// Phase 1: lvoxels on one grid over all media, and their direct light (the LvoxelLight of
// pointcloud/lvoxel_light.h):
//   - per point, spot or directional light, the fraction of its light that reaches the
//     cell centre (visibility x transmittance), so camera rays can apply the light's
//     exact falloff, spot profile and phase function and interpolate only the shadowing;
//   - from the environment and area lights, the light scattered towards the camera with
//     each medium's phase, and their incident light for the cloud.
// Phase 2: the in-scatter source of camera rays read from that light, plus the multiple
// scattering the lvoxels gathered from the cloud.
// Anisotropic media (anisotropicLvoxels) make the lvoxels directional (delta-M,
// docs/pcb.md): the light is carried in spherical harmonics, each lvoxel scatters it with
// its phase less the forward peak, and all light from the sources reaches the lvoxels, the
// surfels and the camera's surface hits through the media without their forward peaks
// (VolumeTransport::transmittance's `reduced`): the peak's light goes on with it.
#include <vector>

#include "pointcloud/lvoxels.h"
#include "pointcloud/point_cloud.h"
#include "pointcloud/pointcloud_settings.h"
#include "src/core/collective.h"
#include "src/render/render_context.h"
#include "src/render/volume_transport.h"
#include "volume/media/media_set.h"

namespace lvox {

// Whether some medium's phase is not isotropic (then the lvoxels of a cloud with multiple
// scattering are directional).
bool anisotropicLvoxels(const MediaSet& media);

// The lvoxel spacing: `requested` (pointcloud.lvoxel_spacing of `sceneFile`) when
// positive, else 1/48 of the largest extent of the media.
float lvoxelSpacing(float requested, const MediaSet& media, const std::string& sceneFile);

// Samples lvoxels in every medium on one grid of the given spacing over all media; their
// light has a transmittance channel per delta light of `lights`. Over several ranks
// (`team`), rank r samples the slices of cells k with k mod N = r and the shares are
// exchanged (cloud_exchange.h); every rank ends with the one-process set. `sampled`
// receives the number of lvoxels this rank sampled. `directional`: the lvoxels scatter
// with their media's phases (anisotropicLvoxels, and a cloud that carries multiple
// scattering: without it the lvoxels hold the exact single scattering). `extinction`:
// the cubes' (pointcloud.lvoxel_extinction).
LvoxelSet sampleSceneLvoxels(const MediaSet& media, float spacing, int samplesPerAxis,
                             LvoxelExtinction extinction, uint64_t seed, const LightSet& lights,
                             bool directional, Collective& team = singleProcess(),
                             size_t* sampled = nullptr);

// Fills every occupied cell with its direct light (see above). Over several ranks
// (`team`), the cells go in blocks of kLvoxelDirectBlock, block b on rank b mod N, and the
// sums over the ranks give each rank every cell's light, as one process computes it.
// Returns the number of cells this rank lit.
inline constexpr size_t kLvoxelDirectBlock = 64;
//
// `skyCubes`: the cloud whose lvoxel cubes the sky's shadow rays cross instead of the
// media (pointcloud.lvoxel_sky_shadow_media), or null. A cell's sky light is the sum of
// lvoxel_light_samples directions, so the detail of the medium below a cell along any one
// of them is averaged away, and the cubes keep the cell's mean transmittance; the one
// direction of a delta light is seen sharp by the camera, and an emitter's light comes
// from near by, so theirs keep the media's exact transmittance.
size_t cacheLvoxelDirectLight(const RenderContext& ctx, const VolumeTransport& volume,
                              LvoxelLight& light, rte::SolveCounts& counts,
                              Collective& team = singleProcess(),
                              const PointCloud* skyCubes = nullptr);

// For ray-traced gathers and camera rays: marks the lvoxels whose cube a surface cuts
// (LvoxelSet::cut; surfaceCutsCube, its 8 corners seen from its centre) and the light's
// cells with a surface within one spacing of their centre (LvoxelLight::markNearSurface;
// the same test on the cube twice as large). Returns how many of each.
struct CutLvoxels {
  size_t lvoxels = 0, cells = 0;
};
CutLvoxels markCutLvoxels(const RayTracer& tracer, PointCloud& cloud);

// The direct light at a cell as the point cloud sees it, light.coefficients() values into
// `out` (spherical_harmonics.h): the area lights' coefficients plus, per delta light,
// L Tr' Yhat(wi) / (4 pi). The first is the phase-averaged in-scatter; Tr' is the
// transmittance without the forward peaks (LvoxelLight::forwardShare; Tr in isotropic
// media).
void cloudDirectLight(const LightSet& lights, LvoxelLight& light, uint32_t slot, RGB* out);

// The in-scatter source along camera rays from the lvoxels' light (the ScatterSource of
// VolumeTransport::radianceWith).
struct PointCloudScatter {
  const LvoxelLight& light;
  const LightSet& lights;
  const MediaSet& media;
  // The light of cells across a surface from x is left out (LvoxelLight::interpolate).
  const RayTracer* tracer = nullptr;
  // Which evaluations test the surfaces towards each point, spot and directional light
  // with a shadow ray (pointcloud.camera_shadow_rays; needs `tracer`); the media's part of
  // the light's transmittance stays the cells' blend. Each ray adds 1 to *shadowRays.
  CameraShadowRays shadowRayTests = CameraShadowRays::kNone;
  uint64_t* shadowRays = nullptr;
  RGB operator()(const Vec3& x, const Vec3& viewDir, const MediumCoefficients* perMedium) const;

 private:
  // Delta light k's blended transmittance at x, with its visibility from a shadow ray where
  // shadowRayTests asks for one.
  void testShadow(const Vec3& x, const LightSample& s, size_t k, LvoxelLightSample& blended) const;
};

}  // namespace lvox
