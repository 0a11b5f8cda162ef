#pragma once
// Settings of the point cloud (the scene file's "pointcloud" section), typed, with their
// parser beside them. Docs: docs/scene-format.md and docs/pointcloud.md.
#include <cstdint>
#include <string>
#include <string_view>

#include "pointcloud/lvoxel_light.h"
#include "src/core/json_fields.h"
#include "src/core/setting_list.h"

namespace lvox {

// How a gather ray finds the surface it sees: the first surfel disk of the cloud
// (Gibson's point-based visibility), or the real surface by ray tracing.
enum class GatherVisibility { kCloud, kRays };
// Where surfels go: uniformly over all surfaces, or where the camera sees them.
enum class SurfelSamplerKind { kUniform, kCamera };
// How an lvoxel's interreflection gather weighs its own cube: sampled by its rays, or by
// 14 fixed directions exact for light of harmonic bands 0-2, where no surface cuts the
// cube (own_cube.h; docs/pcb.md, "The own cube").
enum class LvoxelOwnCube { kRays, kQuadrature };
// The extinction each lvoxel's cube gets: its cell's mean, or the mean scaled so that the
// cube lets through, along its sides, what the medium does on average (lvoxel_sampler.h;
// docs/pcb.md, "Lvoxels that keep the cell's transmittance").
enum class LvoxelExtinction { kMean, kTransmittance };
// Which in-scatter evaluations of camera rays test the surfaces between them and each
// point, spot and directional light with a shadow ray, where the lvoxel cells' blend gives
// the light's visibility otherwise: those where the cells around disagree (a shadow's
// edge), all, or none (docs/pcb.md, "Shadow rays at the cells' shadow edges").
enum class CameraShadowRays { kEdges, kAll, kNone };
// Where the shadow rays of the light the image receives only through the cloud and the
// gathers find the media (the surfels' cached direct light, the delta lights at the
// gathers' hits): the lvoxels' cubes (cube_transmittance.h), or the media themselves
// (docs/pcb.md, "Shadow rays through the cubes").
enum class IndirectShadowMedia { kCubes, kMedia };
// What the last interreflection pass adds: nothing, or the estimated rest of the bounce
// series (light_cache.h, InterreflectionPasses).
enum class BounceTail { kNone, kGeometric };
// How the surfel sides share the interreflection's gather rays: each the same count, or
// half evenly and half by the deviation a preview finds in their light (surfel_rays.h;
// docs/pcb.md, "Rays where the cloud is noisy").
enum class SurfelRayAllocation { kUniform, kVariance };
// How a camera sample's irradiance is fitted to the final gathers around it: their
// weighted mean, or a plane through them evaluated at the sample (local linear regression;
// src/render/indirect_grid.h).
enum class GatherFit { kConstant, kLinear };

// "gather_samples": "auto" (the default): the final gathers trace as many rays as the
// interreflection's gathers did, spread over the final gathers' points, rounded up to a
// multiple of 16, within [kMinAutoGatherSamples, kMaxAutoGatherSamples]. Where the image
// is large against the cloud (the atrium at 512 x 512: 66,049 points, Sponza) that is the
// minimum, 64, the fixed count of stops 38-46; where the cloud's gathers are most of the
// work (small images of lamp-lit rooms) the final gathers, whose noise is there the
// largest term of the error, get more (docs/pcb.md, "How many final gather rays").
constexpr int kAutoGatherSamples = 0;
constexpr int kMinAutoGatherSamples = 64;
// "bounce_mixing_depth": "auto" (the default): the passes run plain and turn to Anderson
// mixing (at depth InterreflectionPasses::kAutoDepth) where the first ones predict many more
// (light_cache.h, InterreflectionPasses::autoMixing; docs/pcb.md, "Mixing the passes").
constexpr int kAutoBounceMixing = -1;
constexpr int kMaxAutoGatherSamples = 512;

struct PointCloudSettings {
  float surfelSpacing = 0.0f;  // 0: derived from the total surface area
  int targetSurfels = 100000;  // used to derive the spacing when it is 0
  SurfelSamplerKind surfelSampler = SurfelSamplerKind::kUniform;
  float lvoxelSpacing = 0.0f;  // 0: derived from the medium size
  int lvoxelSamples = 2;       // jittered samples per axis averaged per lvoxel
  LvoxelExtinction lvoxelExtinction = LvoxelExtinction::kTransmittance;
  int lvoxelGatherSamples = 16;  // sphere rays per lvoxel and scattering pass
  // Rays that sample each lvoxel's near field (within lvoxelNearReach cube sides): the
  // lvoxelGatherSamples rays and short ones in their strata (docs/pcb.md, "The near field").
  int lvoxelNearSamples = 64;
  float lvoxelNearReach = 2.0f;  // lvoxel cube sides; 0: no near field of its own
  LvoxelOwnCube lvoxelOwnCube = LvoxelOwnCube::kQuadrature;
  int bounces = 64;  // interreflection passes (surfels and lvoxels), at most
  // Fewer passes once the light they would still add, estimated from how the last ones
  // shrank, is below this share of the cloud's; 0: always `bounces` (docs/pcb.md, "How
  // many passes").
  float bounceTolerance = 1e-3f;
  BounceTail bounceTail = BounceTail::kGeometric;
  // Anderson mixing of the passes over this many past ones (light_cache.h,
  // InterreflectionPasses); 0: plain passes; kAutoBounceMixing: plain passes that turn to
  // mixing where they converge slowly. Only where the passes stop by the tolerance.
  int bounceMixingDepth = kAutoBounceMixing;
  // Shadow rays per area light (and per sky) for the direct light the cloud caches, in
  // place of render.area_light_samples: a surfel's light reaches the image only through
  // gathers that average many surfels, an lvoxel's through trilinear interpolation
  // (docs/pcb.md, "The cloud's light samples").
  int surfelLightSamples = 4;
  int lvoxelLightSamples = 8;
  // How camera rays blend the lvoxels' direct light between cell centres (lvoxel_light.h;
  // docs/pcb.md, "Blending the cells' light").
  LvoxelLightBlend lvoxelLightBlend = LvoxelLightBlend::kExponential;
  CameraShadowRays cameraShadowRays = CameraShadowRays::kEdges;
  IndirectShadowMedia indirectShadowMedia = IndirectShadowMedia::kCubes;
  // Where the lvoxels' sky samples (lvoxel_light_samples shadow rays to the environment)
  // find the media: the cubes, or the media themselves. The delta lights' and the
  // emitters' shadow rays of the lvoxels always solve the media (docs/pcb.md, "Shadow
  // rays through the cubes").
  IndirectShadowMedia lvoxelSkyShadowMedia = IndirectShadowMedia::kCubes;
  // Surfel spacings; 0 keeps buried surfels. 8 since stop 57: at 4 the atrium's thick
  // overlapping blocks kept 4,400 of their buried surfels (docs/results.md, stop 57).
  float burialReach = 8.0f;
  GatherVisibility gatherVisibility = GatherVisibility::kRays;
  // With `rays` visibility: the triangle lattice's step (surfel spacings) that finds the
  // surfel standing for a gather ray's hit (triangle_surfel_lattice.h); 0: the exact
  // nearest-surfel search at every hit (surfel_lookup.h).
  float hitLatticeStep = 0.7f;
  // Hemisphere rays per surfel side and pass, on average (4 until stop 57).
  int surfelGatherSamples = 8;
  SurfelRayAllocation surfelGatherAllocation = SurfelRayAllocation::kUniform;
  // Final gather rays per pixel (split over its samples), or kAutoGatherSamples: chosen
  // once the cloud is lit (finalGatherSamples).
  int gatherSamples = kAutoGatherSamples;
  // Of those, the rays that aim at the lit surfaces' cells (gather_light_cells.h), as a
  // share of gatherSamples, or of kMinAutoGatherSamples under auto; 0: all cosine rays.
  // Off by default: a quarter of the rays takes 6-7 % off the noise of lamp-lit rooms and
  // adds 2-3 % to sunlit scenes' (docs/pcb.md).
  int gatherLightSamples = 0;
  int gatherSpacing = 2;      // pixels between final gathers; 1: every camera hit
  float gatherFilter = 3.0f;  // tent half-width over final gathers, in gathers
  GatherFit gatherFit = GatherFit::kLinear;
  float lvoxelClusterSolidAngle = 0.0f;  // sr, lvoxel-only nodes; defaultLvoxelClusterSolidAngle
  float clusterSolidAngle = 0.0f;        // sr; 0 = every element exactly
};

// With `rays` visibility 0: gather rays then want the lvoxels only, and marching them
// through the lvoxel lattice visits every one faster than the octree's clusters stood for
// the far ones (docs/pointcloud.md). With `cloud` visibility 0.03 sr.
float defaultLvoxelClusterSolidAngle(GatherVisibility v);

// Reads the "pointcloud" object; unknown keys and out-of-range values throw.
PointCloudSettings parsePointCloudSettings(JsonObject p);
// Every field, as "pointcloud.<key>" and the value the parser reads back.
SettingList describe(const PointCloudSettings& s);

// The final gathers' rays per pixel: gatherSamples, or under auto the rule above, given the
// rays the interreflection's gathers traced (all ranks together) and the number of final
// gather points (grid points, or pixels where every camera hit gathers).
int finalGatherSamples(const PointCloudSettings& s, uint64_t cloudGatherRays,
                       uint64_t finalGatherPoints);
// The count gatherLightSamples is a share of: gatherSamples, or kMinAutoGatherSamples.
int gatherLightSamplesBase(const PointCloudSettings& s);

GatherVisibility parseGatherVisibility(std::string_view name, const std::string& file,
                                       const std::string& field);
std::string_view gatherVisibilityName(GatherVisibility v);
SurfelSamplerKind parseSurfelSampler(std::string_view name, const std::string& file,
                                     const std::string& field);
std::string_view surfelSamplerName(SurfelSamplerKind s);
LvoxelOwnCube parseLvoxelOwnCube(std::string_view name, const std::string& file,
                                 const std::string& field);
std::string_view lvoxelOwnCubeName(LvoxelOwnCube o);
LvoxelExtinction parseLvoxelExtinction(std::string_view name, const std::string& file,
                                       const std::string& field);
std::string_view lvoxelExtinctionName(LvoxelExtinction e);
CameraShadowRays parseCameraShadowRays(std::string_view name, const std::string& file,
                                       const std::string& field);
std::string_view cameraShadowRaysName(CameraShadowRays c);
IndirectShadowMedia parseIndirectShadowMedia(std::string_view name, const std::string& file,
                                             const std::string& field);
std::string_view indirectShadowMediaName(IndirectShadowMedia s);
SurfelRayAllocation parseSurfelRayAllocation(std::string_view name, const std::string& file,
                                             const std::string& field);
std::string_view surfelRayAllocationName(SurfelRayAllocation a);
BounceTail parseBounceTail(std::string_view name, const std::string& file,
                           const std::string& field);
std::string_view bounceTailName(BounceTail t);
GatherFit parseGatherFit(std::string_view name, const std::string& file, const std::string& field);
std::string_view gatherFitName(GatherFit f);
LvoxelLightBlend parseLvoxelLightBlend(std::string_view name, const std::string& file,
                                       const std::string& field);
std::string_view lvoxelLightBlendName(LvoxelLightBlend b);

}  // namespace lvox
