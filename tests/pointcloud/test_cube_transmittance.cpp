#include <gtest/gtest.h>

#include <cmath>

#include "pointcloud/cube_transmittance.h"
#include "pointcloud/lvoxel_sampler.h"
#include "pointcloud/scenes.h"

namespace lvox {
namespace {

// A slab 2 x 2 x 0.5 of sigma_t (0.5, 2, 4), cells of 1/16: the cubes tile it, so the
// chords of those a segment crosses add up to its path in the slab (the lattice's march,
// the same cubes as the medium along any direction). Beer-Lambert to float rounding.
PointCloud slabCloud() {
  const test::BoxMedium m(Vec3(-1, -1, 0), Vec3(1, 1, 0.5f), RGB(0.1f, 0.5f, 1.0f),
                          RGB(0.4f, 1.5f, 3.0f));
  return PointCloud(SurfelSet{}, sampleLvoxels(m, {0.0625f}));
}

TEST(CubeTransmittance, ASegmentThroughASlabIsBeerLambert) {
  const PointCloud cloud = slabCloud();
  ASSERT_TRUE(cloud.lvoxelLattice());
  TraversalScratch scratch;
  const Vec3 dir = normalize(Vec3(0.3f, -0.2f, 1.0f));
  const float path = 0.5f / dir.z;  // through the whole slab
  const RGB t = cubeTransmittance(cloud, Ray{Vec3(0.01f, 0.02f, -0.3f), dir, 0.0f, kInf}, scratch);
  EXPECT_NEAR(t.x, std::exp(-0.5f * path), 1e-5f);
  EXPECT_NEAR(t.y, std::exp(-2.0f * path), 1e-5f);
  EXPECT_NEAR(t.z, std::exp(-4.0f * path), 1e-5f);
  // A segment that ends inside the slab (a shadow ray's light between the cells): only
  // its own part counts.
  const float enter = 0.3f / dir.z;
  const RGB half = cubeTransmittance(
      cloud, Ray{Vec3(0.01f, 0.02f, -0.3f), dir, 0.0f, enter + 0.5f * path}, scratch);
  EXPECT_NEAR(half.y, std::exp(-2.0f * 0.5f * path), 1e-5f);
  // A segment that misses the slab.
  EXPECT_EQ(cubeTransmittance(cloud, Ray{Vec3(0, 0, -0.3f), Vec3(0, 0, -1), 0.0f, kInf}, scratch),
            RGB(1.0f));
}

TEST(CubeTransmittance, AnOpaqueSegmentStopsEarlyAtZero) {
  // Optical depth 4 x 20 = 80 along x: the walk stops past 30 in every colour, and what it
  // returns is below exp(-30).
  const test::BoxMedium m(Vec3(0, 0, 0), Vec3(20, 1, 1), RGB(0.0f), RGB(4.0f));
  const PointCloud cloud(SurfelSet{}, sampleLvoxels(m, {0.5f}));
  TraversalScratch scratch;
  const RGB t =
      cubeTransmittance(cloud, Ray{Vec3(-1, 0.5f, 0.5f), Vec3(1, 0, 0), 0.0f, kInf}, scratch);
  EXPECT_LT(maxComponent(t), std::exp(-kOpaqueDepth) * 1.0001f);
  EXPECT_GT(maxComponent(t), 0.0f);
  EXPECT_LT(scratch.stats.elementsVisited, 20u);  // 15 cubes of depth 2 reach 30 of the 80
}

}  // namespace
}  // namespace lvox
