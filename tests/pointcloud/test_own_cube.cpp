#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "pointcloud/gather.h"
#include "pointcloud/lvoxel_sampler.h"
#include "pointcloud/own_cube.h"
#include "pointcloud/scenes.h"
#include "src/core/spherical_harmonics.h"

namespace lvox {
namespace {

// Calls f(d, w / (4 pi) dw) over the sphere for the cube of half-size h and extinction
// sigmaT seen from its centre, w = 1 - exp(-sigmaT chord(d)): a midpoint rule over
// n x n directions uniform in (cos theta, phi), independent of own_cube.h's face rule.
template <class F>
void overTheSphere(double sigmaT, double h, int n, F&& f) {
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const auto steps = static_cast<float>(n);
      const Vec3 d = uniformSphere((static_cast<float>(i) + 0.5f) / steps,
                                   (static_cast<float>(j) + 0.5f) / steps);
      const double m = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
      f(d, (1.0 - std::exp(-sigmaT * h / m)) / (static_cast<double>(n) * n));
    }
}

// Collects the 14 directions and weights a sink is sent.
struct DirectionSink {
  std::vector<Vec3> directions;
  std::vector<float> weights;
  void beginRay(const Vec3& d) { directions.push_back(d); }
  void lvoxel(uint32_t, const RGB& w) { weights.push_back(w.x); }
};

TEST(OwnCube, FourteenDirectionsCoupleTheHarmonicsAsTheWholeSphereDoes) {
  // For optical half-sizes 0.05 to 8: sum over the 14 directions of w Yhat_k Yhat_q, every
  // pair of the 9 harmonics of bands 0-2, against the same integral over the sphere by a
  // midpoint rule of 1,000 x 1,000 directions (its own error, at the cube's edges, about
  // 5e-6 of the mean): within 2e-5 of the mean weight (measured 5e-6). Off the diagonal
  // both are 0 by the cube's symmetry; on it band 2 has two values, both matched (with the
  // quartic integral from a rule on the whole face, 1e-4 off, they were 2e-4 apart).
  for (const float tau : {0.05f, 0.5f, 2.0f, 8.0f}) {
    const test::BoxMedium m(Vec3(-0.1f), Vec3(0.1f), RGB(0.0f), RGB(10.0f * tau));
    const LvoxelSet cube = sampleLvoxels(m, {0.2f});
    ASSERT_EQ(cube.size(), 1u);
    DirectionSink fourteen;
    ownCubeInto(cube, 0, fourteen);
    ASSERT_EQ(fourteen.directions.size(), 14u);
    double sphere[kShCoefficients][kShCoefficients] = {};
    overTheSphere(10.0 * tau, 0.1, 1000, [&](const Vec3& d, double w) {
      float y[kShCoefficients];
      shBasis(d, kShCoefficients, y);
      for (int k = 0; k < kShCoefficients; ++k)
        for (int q = 0; q < kShCoefficients; ++q) sphere[k][q] += w * y[k] * y[q];
    });
    double worst = 0.0;
    for (int k = 0; k < kShCoefficients; ++k)
      for (int q = 0; q < kShCoefficients; ++q) {
        double sum = 0.0;
        for (size_t n = 0; n < 14; ++n) {
          float y[kShCoefficients];
          shBasis(fourteen.directions[n], kShCoefficients, y);
          sum += fourteen.weights[n] * y[k] * y[q];
        }
        worst = std::max(worst, std::abs(sum - sphere[k][q]) / sphere[0][0]);
      }
    for (float w : fourteen.weights) EXPECT_GE(w, 0.0f);
    std::printf("tau %.2f: mean weight %.7f, worst coupling off by %.2g of it\n", tau, sphere[0][0],
                worst);
    EXPECT_LT(worst, 2e-5) << tau;
  }
}

TEST(OwnCube, PlanesThroughTheCubeCutItAndPlanesOnItsFacesDoNot) {
  const Vec3 c(0.3f, 0.2f, 0.1f);
  const float h = 0.1f;
  auto cuts = [&](float y) {  // a large horizontal quad at height y
    TriangleMesh mesh;
    test::addQuad(mesh, Vec3(-5, y, -5), Vec3(-5, y, 5), Vec3(5, y, 5), Vec3(5, y, -5), 0);
    return surfaceCutsCube(RayTracer(mesh), c, h);
  };
  EXPECT_TRUE(cuts(0.2f));    // through the centre
  EXPECT_TRUE(cuts(0.29f));   // a thin slice off the top
  EXPECT_FALSE(cuts(0.3f));   // on the top face
  EXPECT_FALSE(cuts(0.35f));  // above it
  // A tilted plane that leaves only one corner on its far side.
  TriangleMesh mesh;
  const Vec3 corner = c + Vec3(h, h, h);
  const Vec3 n = normalize(Vec3(1, 1, 1));
  const Vec3 q = corner - n * 0.02f;  // 0.02 inside that corner
  const Vec3 u = normalize(Vec3(1, -1, 0)), v = cross(n, u);
  test::addQuad(mesh, q - u - v, q + u - v, q + u + v, q - u + v, 0);
  EXPECT_TRUE(surfaceCutsCube(RayTracer(mesh), c, h));
}

// An absorbing and scattering box (sigma_t 5, lvoxels 0.2) whose lvoxels all carry source
// radiance 1, and its lvoxel at (0.1, 0.1, 0.3).
PointCloud glowingBox(uint32_t& inner) {
  const test::BoxMedium m(Vec3(-1, -1, -1), Vec3(1, 1, 1), RGB(0.25f), RGB(4.75f));
  PointCloud cloud(SurfelSet{}, sampleLvoxels(m, {0.2f}));
  LvoxelLight& light = cloud.mutableLvoxels().light;
  for (uint32_t s = 0; s < light.occupiedCount(); ++s) light.directInScatter(s)[0] = RGB(1.0f);
  cloud.updateAggregates();
  for (uint32_t i = 0; i < cloud.lvoxels().size(); ++i)
    if (length(cloud.lvoxels().position[i] - Vec3(0.1f, 0.1f, 0.3f)) < 0.01f) inner = i;
  return cloud;
}

TEST(OwnCube, GatherWithItsOwnCubeFromTheQuadratureHasTheRaysExpectation) {
  // The box's in-scatter at the inner lvoxel's centre with 4,096 rays, the own cube from
  // the rays and from its 14 directions: within 5e-4 (the rays' own noise), and most of
  // it is the own cube's. Without a tracer (which says whether a surface cuts the cube)
  // the rays keep it: the same result to the bit.
  uint32_t own = 0;
  const PointCloud cloud = glowingBox(own);
  const Vec3 p = cloud.lvoxels().position[own];
  const TriangleMesh none;
  const RayTracer tracer(none);
  auto gather = [&](bool quadrature, bool withTracer) {
    GatherOptions o;
    o.samples = 4096;
    o.tracer = withTracer ? &tracer : nullptr;
    o.ownLvoxel = quadrature ? static_cast<long>(own) : -1;
    Rng rng(1, 2);
    return gatherInScatter(cloud, p, Vec3(0, 0, 1), IsotropicPhase{}, o, rng).x;
  };
  const double rays = gather(false, true), quadrature = gather(true, true);
  std::printf("in-scatter: rays %.6f, own cube from the quadrature %.6f\n", rays, quadrature);
  EXPECT_NEAR(quadrature / rays, 1.0, 5e-4);
  EXPECT_GT(quadrature, 0.9);
  EXPECT_EQ(gather(true, false), gather(false, false));
}

}  // namespace
}  // namespace lvox
