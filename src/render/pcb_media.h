#pragma once
// Participating media in pcb mode (Gibson 2011, extended with the RTE solvers).
// Phase 1: lvoxels on one grid over all media, and their direct light:
//   - per point, spot or directional light, the fraction of its light that reaches the
//     lvoxel centre (visibility x transmittance), so camera rays can apply the light's
//     exact falloff, spot profile and phase function and interpolate only the shadowing;
//   - from the environment and area lights, the in-scattered radiance for an isotropic
//     phase (the cache keeps no direction), plus the multiple-scattering term the
//     lvoxels gather from the cloud.
// Phase 2: the in-scatter source of camera rays read from that field.
#include <vector>

#include "pointcloud/lvoxels.h"
#include "src/render/lvoxel_field.h"
#include "src/render/render_context.h"
#include "src/render/volume_transport.h"
#include "volume/media/media_set.h"

namespace lvox {

// The lvoxel spacing: `requested` (pointcloud.lvoxel_spacing of `sceneFile`) when
// positive, else 1/48 of the largest extent of the media.
float lvoxelSpacing(float requested, const MediaSet& media, const std::string& sceneFile);

// Samples lvoxels in every medium on the field's grid and marks their cells occupied.
LvoxelSet sampleSceneLvoxels(const MediaSet& media, int samplesPerAxis, uint64_t seed,
                             LvoxelField& field);

// Channel layout of the field: one per delta light, then the isotropic in-scatter.
inline size_t lvoxelFieldChannels(const LightSet& lights) { return lights.lights().size() + 1; }

// Fills every occupied cell with its direct light (see above).
void cacheLvoxelDirectLight(const RenderContext& ctx, const VolumeTransport& volume,
                            LvoxelField& field, rte::SolveCounts& counts);

// In-scattered radiance at a cell for the point cloud's isotropic cache: the phase-averaged
// direct light, sum over delta lights of L Tr / (4 pi) plus the isotropic channel.
RGB phaseAveragedDirect(const LightSet& lights, const LvoxelField& field, uint32_t slot);

// Adds the lvoxels' gathered multiple scattering to the isotropic channel (lvoxels of
// overlapping media in one cell are averaged).
void addMultipleScattering(const LvoxelSet& lvoxels, LvoxelField& field);

// The in-scatter source along camera rays from the field (the ScatterSource of
// VolumeTransport::radianceWith).
struct PointCloudScatter {
  const LvoxelField& field;
  const LightSet& lights;
  const MediaSet& media;
  RGB operator()(const Vec3& x, const Vec3& viewDir, const MediumCoefficients* perMedium) const;
};

}  // namespace lvox
