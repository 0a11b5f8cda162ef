#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "pointcloud/gather.h"
#include "pointcloud/gather_operator.h"
#include "pointcloud/scenes.h"
#include "pointcloud/surfel_sampler.h"
#include "sphere_quadrature.h"

namespace lvox {
namespace {

TEST(SurfelCluster, ClampedCosineCoefficientsAreTheLobesProjection) {
  // c_k = mean over the sphere of max(0, m.w) Yhat_k(w) (spherical_harmonics.h).
  const Vec3 m = normalize(Vec3(0.3f, -0.5f, 0.8f));
  float c[kShCoefficients];
  clampedCosineCoefficients(m, c);
  for (int k = 0; k < kShCoefficients; ++k) {
    const double expected = test::sphereMean([&](const Vec3& w) {
      float y[kShCoefficients];
      shBasis(w, kShCoefficients, y);
      return std::max(0.0f, dot(m, w)) * y[k];
    });
    EXPECT_NEAR(c[k], expected, 2e-4) << "k " << k;
  }
}

// Directions spread over the sphere (a Fibonacci lattice).
std::vector<Vec3> sphereDirections(int n) {
  std::vector<Vec3> d;
  for (int i = 0; i < n; ++i) {
    const float z = 1.0f - (2.0f * static_cast<float>(i) + 1.0f) / static_cast<float>(n);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = 2.39996323f * static_cast<float>(i);
    d.push_back(Vec3(r * std::cos(phi), r * std::sin(phi), z));
  }
  return d;
}

TEST(SurfelCluster, AFlatClusterLitOnOneSideIsExactFromBothSides) {
  // A tilted square of surfels, radiance (1, 0.5, 0.25) in front and 0 behind, in one
  // leaf: its cluster must show the front's radiance from every direction on the front
  // side and nothing from behind (Christensen's power / area ratio shows 0.94-1.09 of it in
  // front and 6 % of it behind), to float rounding, and block the disks' projected area
  // from both sides. With
  // its back sides enclosed it blocks nothing from behind, as the disks then let rays by.
  TriangleMesh mesh;
  const Vec3 n = normalize(Vec3(1, 2, 3)), u = normalize(cross(n, Vec3(1, 0, 0))), v = cross(n, u);
  test::addQuad(mesh, u * -0.5f + v * -0.5f, u * 0.5f + v * -0.5f, u * 0.5f + v * 0.5f,
                u * -0.5f + v * 0.5f, 0);
  SurfelSet s = sampleSurfelsUniform(mesh, {Material{}}, {0.1f, 1.15f, 3});
  const RGB lit(1.0f, 0.5f, 0.25f);
  s.radianceFront.assign(s.size(), lit);
  s.radianceBack.assign(s.size(), RGB(0.0f));
  const size_t count = s.size();
  SurfelSet enclosedBack = s;
  enclosedBack.enclosedSides.assign(count, 2);
  OctreeSettings one;
  one.leafSize = 1000;
  const PointCloud pc(std::move(s), LvoxelSet{}, one), closed(std::move(enclosedBack), {}, one);
  ASSERT_EQ(pc.nodes().size(), 1u);
  const SurfelCluster &c = pc.surfelClusters()[0], &cc = closed.surfelClusters()[0];
  const Vec3 front = dot(pc.surfels().normal(0), n) > 0.0f ? n : -n;
  for (const Vec3& d : sphereDirections(200)) {
    const float cosine = dot(-d, front);  // the viewer is on the front side when > 0
    if (std::abs(cosine) < 0.02f) continue;
    const RGB l = c.radiance(d);
    const RGB expected = cosine > 0.0f ? lit : RGB(0.0f);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(l[ch], expected[ch], 5e-4f) << d;
    const Vec3 e = c.cover.diagonal();
    const float box =
        std::abs(d.x) * e.y * e.z + std::abs(d.y) * e.x * e.z + std::abs(d.z) * e.x * e.y;
    const float blocked = std::min(1.0f, c.diskArea * std::abs(cosine) / box);
    EXPECT_NEAR(c.coverage(d), blocked, 1e-4f) << d;
    if (cosine > 0.0f) {
      EXPECT_NEAR(cc.coverage(d), blocked, 1e-4f) << d;
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(cc.radiance(d)[ch], lit[ch], 5e-4f) << d;
    } else {
      EXPECT_EQ(cc.coverage(d), 0.0f) << d;
    }
  }
  std::printf("flat cluster of %zu surfels: exact from %d directions\n", count, 200);
}

// A plate of surfels (the box [-0.5, 0.5] x [-h, h] x [-0.5, 0.5]) lit from above: the
// outer side of its top face has radiance `top` (brighter towards +x), every other outer
// side is dark, and the inner sides are enclosed, as removeBuriedSurfels marks them.
PointCloud litPlate(float h, const RGB& top) {
  TriangleMesh mesh;
  test::addBox(mesh, Vec3(-0.5f, -h, -0.5f), Vec3(0.5f, h, 0.5f), 0);
  SurfelSet s = sampleSurfelsUniform(mesh, {Material{}}, {0.02f, 1.15f, 5});
  for (size_t i = 0; i < s.size(); ++i) {
    // addBox's normals point inwards: the front is the inner side.
    const bool topFace = s.position[i].y > 0.99f * h && s.normal[i].y < -0.5f;
    s.radianceFront[i] = RGB(0.0f);
    s.radianceBack[i] = topFace ? top * (1.0f + s.position[i].x) : RGB(0.0f);
    s.enclosedSides[i] = 1;
  }
  return PointCloud(std::move(s), LvoxelSet{});
}

// The cloud's radiance averaged over a grid of parallel rays from `eye` through a square
// of side 1.6 around the origin: what a distant viewer sees of the plate.
RGB seen(const PointCloud& pc, const Vec3& eye, const GatherOptions& o) {
  const Vec3 w = normalize(-eye);
  const Vec3 u = normalize(cross(w, std::abs(w.y) < 0.9f ? Vec3(0, 1, 0) : Vec3(1, 0, 0)));
  const Vec3 v = cross(w, u);
  const int n = 128;
  RGB sum(0.0f);
  TraversalScratch scratch;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const float a = 1.6f * ((static_cast<float>(i) + 0.5f) / n - 0.5f);
      const float b = 1.6f * ((static_cast<float>(j) + 0.5f) / n - 0.5f);
      sum += gatherRay(pc, Ray{eye + u * a + v * b, w, 0.0f, kInf}, o, scratch);
    }
  return sum / static_cast<float>(n * n);
}

TEST(SurfelCluster, APlateLitOnOneSideLooksLikeItsSurfelsFromBothSides) {
  // Issue 13's test: a cluster lit on one side only, seen from both sides, against the
  // exact traversal of its ~6000 surfels. From 8 units away with clusters up to 0.1 sr
  // the plate is its root cluster. The front/back proxies this replaced averaged both
  // faces' sides about one axis (the top's lit outer side with the bottom's dark inner
  // one) and showed 43 % of the exact radiance from above, 48 % at 60 degrees.
  // Measured: 4.4 % darker from above, 6.2 % at 60 degrees, and 2.1 % of the lit view's
  // radiance seen from below (the plate is not flat: its rims make the even harmonics'
  // correction approximate, surfel_cluster.h). Bounds 8 % and 3 %; rays see no noise here.
  const RGB top(1.0f, 0.6f, 0.3f);
  const PointCloud pc = litPlate(0.02f, top);
  GatherOptions exact, clusters;
  clusters.maxSolidAngle = 0.1f;
  const RGB above = seen(pc, Vec3(0.1f, 8.0f, 0.2f), exact);
  ASSERT_GT(above.x, 0.3f);
  struct View {
    const char* name;
    Vec3 eye;
    float bound;  // of the lit view's radiance
  };
  const View views[] = {{"above", Vec3(0.1f, 8.0f, 0.2f), 0.08f},
                        {"60 degrees", Vec3(8.0f * 0.866f, 4.0f, 0.3f), 0.08f},
                        {"below", Vec3(0.2f, -8.0f, -0.1f), 0.03f},
                        {"below, 60 degrees", Vec3(-6.9f, -4.0f, 0.3f), 0.03f}};
  for (const View& view : views) {
    const RGB e = seen(pc, view.eye, exact), c = seen(pc, view.eye, clusters);
    std::printf("%-18s exact (%.4f %.4f %.4f) clusters (%.4f %.4f %.4f)\n", view.name, e.x, e.y,
                e.z, c.x, c.y, c.z);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(c[ch], e[ch], view.bound * above[ch]) << view.name;
  }
}

// A ball of surfels (radius 0.5) lit from `sun`: the outer side of each has radiance
// max(0, n.sun); inner sides are enclosed.
PointCloud litBall(const Vec3& sun) {
  TriangleMesh mesh;
  test::addSphere(mesh, Vec3(0, 0, 0), 0.5f, 24, 48, 0);
  SurfelSet s = sampleSurfelsUniform(mesh, {Material{}}, {0.02f, 1.15f, 5});
  for (size_t i = 0; i < s.size(); ++i) {
    const bool outward = dot(s.normal[i], s.position[i]) > 0.0f;
    const Vec3 out = outward ? s.normal[i] : -s.normal[i];
    (outward ? s.radianceFront : s.radianceBack)[i] = RGB(std::max(0.0f, dot(out, sun)));
    (outward ? s.radianceBack : s.radianceFront)[i] = RGB(0.0f);
    s.enclosedSides[i] = outward ? 2 : 1;
  }
  return PointCloud(std::move(s), LvoxelSet{});
}

TEST(SurfelCluster, TheOperatorRecordsClustersAsTheGatherSeesThem) {
  // The gather operator's surfel-cluster columns (the power coefficients, weighted by
  // the ray's direction) give what the gathers give, for any radiance.
  const Vec3 sun = normalize(Vec3(-1, 2, 1));
  const PointCloud pc = litBall(sun);
  GatherOptions o;
  o.samples = 1024;
  o.maxSolidAngle = 0.1f;
  const std::vector<Vec3> points = {{2, 0, 0}, {0, -2, 0.5f}, {-1.2f, 1.2f, 1.2f}};
  const GatherOperator op(
      pc, points.size(), [&](size_t r, GatherRecorder& rec, TraversalScratch& scratch) {
        Rng rng(7, r);
        gatherIrradianceInto(pc, points[r], normalize(-points[r]), o, rng, scratch, rec);
      });
  std::vector<RGB> out;
  op.apply(op.columns().values(pc, RGB(0.0f)), out);
  for (size_t r = 0; r < points.size(); ++r) {
    Rng rng(7, r);
    const RGB e = gatherIrradiance(pc, points[r], normalize(-points[r]), o, rng);
    EXPECT_GT(e.x, 0.0f) << r;
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(out[r][ch], e[ch], 1e-5f + 1e-4f * e[ch]) << r;
  }
}

}  // namespace
}  // namespace lvox
