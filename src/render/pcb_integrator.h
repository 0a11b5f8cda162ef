#pragma once
// --mode pcb and pcb-surfels: the two-phase point-based renderer (Gibson 2011).
// Phase 1 samples surfels (and, in pcb mode, lvoxels) into one octree and caches direct
// light on them; phase 2 shades camera hits with exact direct light plus indirect light
// gathered from the cloud by front-to-back traversal.
#include <memory>

#include "pointcloud/point_cloud.h"
#include "src/render/render_context.h"
#include "src/render/report.h"
#include "src/render/sampler_counters.h"
#include "src/render/tile_renderer.h"

namespace lvox {

// Phase 1. Records times, counts and memory in the report.
std::unique_ptr<PointCloud> buildPointCloud(const RenderContext& ctx, Report& report);

// Phase 2 for one camera sample.
PixelSampler pcbSampler(const RenderContext& ctx, const PointCloud& cloud, int spp,
                        SamplerCounters& counters);

}  // namespace lvox
