#pragma once
// --mode pcb and pcb-surfels: the two-phase point-based renderer (Gibson 2011).
// Phase 1 samples surfels (and, in pcb mode, lvoxels) into one octree and caches direct
// light on them; phase 2 shades camera hits with exact direct light plus indirect light
// gathered from the cloud by front-to-back traversal, and solves the RTE along camera
// rays through media: with the in-scatter source read from the lvoxels (pcb), or with
// exact single scattering (pcb-surfels, the traditional baseline).
#include <memory>
#include <string>

#include "pointcloud/point_cloud.h"
#include "pointcloud/pointcloud_settings.h"
#include "pointcloud/surfel_lookup.h"
#include "pointcloud/triangle_surfel_lattice.h"
#include "src/core/collective.h"
#include "src/render/delta_hit_light.h"
#include "src/render/indirect_grid.h"
#include "src/render/render_context.h"
#include "src/render/report.h"
#include "src/render/sampler_counters.h"
#include "src/render/tile_renderer.h"
#include "src/render/volume_transport.h"

namespace lvox {

// What phase 1 leaves for phase 2.
struct PointBasedCache {
  std::unique_ptr<PointCloud> cloud;  // its lvoxels hold their light (LvoxelLight)
  bool lvoxels = false;               // pcb mode in a scene with media
  // Directional lvoxels (anisotropic media): light from the sources reaches surfaces
  // through the media without their phases' forward peaks (pcb_media.h).
  bool reducedShadows = false;
  IndirectGrid gathers;  // final gathers at a reduced rate; empty: at every camera hit
  // The final gathers' rays per pixel (finalGatherSamples: gather_samples, or auto's).
  int gatherSamples = kMinAutoGatherSamples;
  // "gather_visibility": "rays" only: the surfel standing for each gather ray's hit, from
  // the triangle lattice, or with "hit_lattice_step" 0 from the exact lookup (one is set).
  std::unique_ptr<TriangleSurfelLattice> lattice;
  std::unique_ptr<SurfelLookup> lookup;
  // With ray-traced visibility and delta lights in the scene: their light at each gather hit, which
  // the surfels then leave out (delta_hit_light.h).
  std::unique_ptr<DeltaHitLight> hitLight;
  // With ray-traced visibility and "gather_light_samples" > 0: the lit surfaces' cells the
  // final gathers aim a share of their rays at (gather_light_cells.h).
  std::unique_ptr<GatherLightCells> gatherLights;
  // With ray-traced visibility and a constant environment: the final gathers' rays that leave the
  // cloud see it, through the lvoxels they passed, and the camera hits' direct light leaves it out;
  // with interreflection passes too, the surfels' gathers bring their share of it and their direct
  // light leaves it out (docs/pcb.md, "The environment in the gathers").
  bool environmentInGathers = false;
  bool surfelEnvironmentInGathers = false;
};

// Phase 1. Records times, counts and memory in the report. `sceneFile` names the source of
// `settings` in errors found only now (an lvoxel spacing far too small for the media).
// Over several ranks (`team`), the cloud is built once across them: each samples and
// probes its share of the surfels, samples and lights its share of the lvoxels, and the
// pieces are exchanged (cloud_exchange.h; each rank's share is in report.work); the
// octree is built by every rank from the same elements. The surfels' direct light, the
// interreflection's gathers and the screen grid's gathers are split too (light_cache.h,
// indirect_grid.h): each rank ends with the cloud and caches one process builds.
PointBasedCache buildPointCloud(const RenderContext& ctx, const VolumeTransport& volume,
                                const PointCloudSettings& settings, const std::string& sceneFile,
                                Report& report, Collective& team = singleProcess());

// Phase 2 for one camera sample.
PixelSampler pcbSampler(const RenderContext& ctx, const VolumeTransport& volume,
                        const PointBasedCache& cache, const PointCloudSettings& settings, int spp,
                        SamplerCounters& counters);

}  // namespace lvox
