#pragma once
// The transmittance of the medium as the cloud holds it: exp(-sum sigma_t x chord) over
// the lvoxels' cubes a segment crosses (the lattice's march, and the lvoxel clusters
// beyond their free reach when the options allow them). Shadow rays whose light only
// feeds the cloud's interreflection take it instead of the medium's own voxels
// (docs/pcb.md, "Shadow rays through the cubes"): a few cells in place of a quadrature
// over every voxel, with the transmittance the cubes keep on average (lvoxel_sampler.h).
#include "pointcloud/point_cloud.h"
#include "pointcloud/traversal.h"

namespace lvox {

// `ray`: the segment [tmin, tmax]. Past an optical depth of kOpaqueDepth in every colour
// the walk stops: the rest cannot matter (exp(-30) ~ 1e-13).
inline constexpr float kOpaqueDepth = 30.0f;
RGB cubeTransmittance(const PointCloud& cloud, const Ray& ray, TraversalScratch& scratch,
                      const TraversalOptions& options = TraversalOptions{0.0f, 0.0f, false});

}  // namespace lvox
