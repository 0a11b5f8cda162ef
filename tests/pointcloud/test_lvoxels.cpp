#include <gtest/gtest.h>

#include <cmath>

#include "pointcloud/gather.h"
#include "pointcloud/lvoxel_sampler.h"
#include "pointcloud/scenes.h"

namespace lvox {
namespace {

// Records the optical depth sum(sigma_t * chord) of the lvoxels along a ray.
struct OpticalDepth {
  const PointCloud& cloud;
  double tau = 0.0;
  void surfel(uint32_t, float, bool) {}
  bool surfelCluster(uint32_t, float, bool, float) { return true; }
  bool lvoxel(uint32_t i, float t0, float t1) {
    tau += cloud.lvoxels().sigmaT(i).x * (t1 - t0);
    return true;
  }
  bool lvoxelCluster(uint32_t, float, float) { return true; }
};

double opticalDepth(const PointCloud& cloud, const Ray& ray) {
  OpticalDepth v{cloud};
  TraversalScratch scratch;
  traverse(cloud, ray, v, TraversalOptions{}, scratch);
  return v.tau;
}

Ray throughSlabMiddle(const Vec3& centre, float thetaDeg, float phiDeg) {
  const float th = thetaDeg * kPi / 180.0f, ph = phiDeg * kPi / 180.0f;
  const Vec3 dir(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
  return Ray{centre - dir * 10.0f, dir, 0.0f, kInf};
}

TEST(Lvoxels, NoMediumNoLvoxels) {
  // Zero coefficients everywhere, and a medium with no active region.
  const test::BoxMedium empty(Vec3(0, 0, 0), Vec3(1, 1, 1), RGB(0.0f), RGB(0.0f));
  EXPECT_EQ(sampleLvoxels(empty, {0.1f}).size(), 0u);
  test::BoxMedium inactive(Vec3(0, 0, 0), Vec3(1, 1, 1), RGB(1.0f), RGB(1.0f));
  inactive.active.clear();
  EXPECT_EQ(sampleLvoxels(inactive, {0.1f}).size(), 0u);
  const PointCloud cloud(SurfelSet{}, LvoxelSet{});
  EXPECT_TRUE(cloud.empty());
  EXPECT_EQ(cloud.memoryBytes(), 0u);
}

TEST(Lvoxels, CoefficientsAreAveragedOverTheCube) {
  // The medium fills exactly the lower half (in x) of the last cell column: 2x2x2
  // stratified samples put 4 of 8 samples inside, so the average is exactly half.
  const test::BoxMedium m(Vec3(0, 0, 0), Vec3(0.3125f, 0.25f, 0.25f), RGB(1, 2, 3), RGB(4, 5, 6));
  LvoxelSettings s;
  s.spacing = 0.125f;
  const LvoxelSet l = sampleLvoxels(m, s);
  ASSERT_EQ(l.size(), 3u * 2u * 2u);
  for (size_t i = 0; i < l.size(); ++i) {
    const float f = l.position[i].x > 0.25f ? 0.5f : 1.0f;
    EXPECT_NEAR(l.sigmaA[i].y, 2.0f * f, 1e-5f);
    EXPECT_NEAR(l.sigmaS[i].z, 6.0f * f, 1e-5f);
    EXPECT_FLOAT_EQ(l.halfSize[i], 0.0625f);
  }
}

TEST(Lvoxels, SlabTransmittanceMatchesBeerLambert) {
  // Slab 2 x 2 x 0.5, sigma_t = 2 (tau = 1 at normal incidence), spacing 1/16 (8 cells
  // through the thickness). Cubes of one grid tile space, so the chords of the cubes a
  // ray crosses add up to its path length in the slab: exact for any direction.
  const float d = 0.5f, sigmaT = 2.0f;
  const test::BoxMedium m(Vec3(-1, -1, 0), Vec3(1, 1, d), RGB(0.5f), RGB(1.5f));
  const PointCloud cloud(SurfelSet{}, sampleLvoxels(m, {0.0625f}));
  const Vec3 middle(0.013f, -0.021f, 0.5f * d);
  for (float theta : {0.0f, 30.0f, 60.0f})
    for (float phi : {0.0f, 37.0f}) {
      const double expected = std::exp(-sigmaT * d / std::cos(theta * kPi / 180.0f));
      const double got = std::exp(-opticalDepth(cloud, throughSlabMiddle(middle, theta, phi)));
      EXPECT_NEAR(got / expected, 1.0, 0.02) << "theta " << theta << " phi " << phi;
    }
}

TEST(Lvoxels, SlabNotAlignedWithTheGridStaysWithinTheBoundaryCellBound) {
  // Thickness 0.47 with spacing 0.06: the boundary cell layer is partly filled and its
  // averaged sigma carries the filled fraction, estimated from 4 jittered strata in z:
  // |tau error| <= sigma_t * spacing / (2 * 4) per crossing of that layer = 0.015.
  const float d = 0.47f, sigmaT = 2.0f;
  const test::BoxMedium m(Vec3(-1, -1, 0), Vec3(1, 1, d), RGB(0.0f), RGB(2.0f));
  LvoxelSettings s;
  s.spacing = 0.06f;
  s.samplesPerAxis = 4;
  const PointCloud cloud(SurfelSet{}, sampleLvoxels(m, s));
  for (float theta : {0.0f, 45.0f}) {
    const double tau = sigmaT * d / std::cos(theta * kPi / 180.0f);
    const double got =
        opticalDepth(cloud, throughSlabMiddle(Vec3(0.01f, 0.02f, 0.2f), theta, 20.0f));
    EXPECT_NEAR(got, tau, 0.015 / std::cos(theta * kPi / 180.0f) + 1e-3) << theta;
  }
}

TEST(Lvoxels, InScatterFurnaceInsideAMedium) {
  // Volume white furnace: non-absorbing medium whose lvoxels all carry source radiance
  // 1, background radiance 1: every gather ray returns exactly 1, so the isotropic
  // in-scatter is 1 whatever the transmittance (up to float rounding).
  const test::BoxMedium m(Vec3(-1, -1, -1), Vec3(1, 1, 1), RGB(0.0f), RGB(3.0f));
  PointCloud cloud(SurfelSet{}, sampleLvoxels(m, {0.1f}));
  std::fill(cloud.mutableLvoxels().directInScatter.begin(),
            cloud.mutableLvoxels().directInScatter.end(), RGB(1.0f));
  cloud.updateAggregates();
  GatherOptions o;
  o.samples = 64;
  o.background = RGB(1.0f);
  Rng rng(1, 2);
  const RGB ls =
      gatherInScatter(cloud, Vec3(0.1f, 0.2f, 0.3f), Vec3(0, 0, 1), IsotropicPhase{}, o, rng);
  EXPECT_NEAR(ls.x, 1.0f, 1e-4f);
  EXPECT_NEAR(ls.z, 1.0f, 1e-4f);
  // Without the background, the result is 1 - mean transmittance to the medium's edge:
  // for tau >= 3 at the nearest face this is above 0.9.
  o.background = RGB(0.0f);
  const RGB inner = gatherInScatter(cloud, Vec3(0, 0, 0), Vec3(0, 0, 1), IsotropicPhase{}, o, rng);
  EXPECT_GT(inner.x, 0.9f);
  EXPECT_LT(inner.x, 1.0f);
}

}  // namespace
}  // namespace lvox
