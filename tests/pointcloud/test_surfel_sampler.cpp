#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "pointcloud/scenes.h"
#include "pointcloud/surfel_sampler.h"
#include "src/core/error.h"

namespace lvox {
namespace {

std::vector<Material> whiteMaterial() { return {Material{"white", RGB(0.8f), RGB(0.0f)}}; }

TEST(SurfelSampler, CountMatchesAreaOverSpacingSquaredOnLargeTriangles) {
  TriangleMesh mesh;
  test::addBox(mesh, Vec3(0, 0, 0), Vec3(1, 2, 3), 0);
  const float spacing = 0.02f;
  const SurfelSet s = sampleSurfelsUniform(mesh, whiteMaterial(), {spacing, 1.15f, 7});
  // Lattice sites inside the faces (area / s^2 = 55000) plus the sites within the
  // covering radius R = 0.6204 s outside each face's border, moved onto it: R / s^2 per
  // unit of border length. The border is 4 edges per face, 48 in all (1489 sites, 2.7 %).
  const double borderLength = 2.0 * 4.0 * (1.0 + 2.0 + 3.0);
  const double expected =
      test::meshArea(mesh) / (spacing * spacing) + 0.6204 * borderLength / spacing;
  // Whether a row of the lattice falls in a border strip depends on the offset: 2 %.
  EXPECT_NEAR(static_cast<double>(s.size()) / expected, 1.0, 0.02);
  for (size_t i = 0; i < s.size(); ++i) {
    ASSERT_NEAR(s.radius[i], spacing / std::sqrt(kPi) * 1.15f, 1e-6f);
    ASSERT_NEAR(length(s.normal[i]), 1.0f, 1e-5f);
  }
}

TEST(SurfelSampler, SmallTrianglesGetTheirFairShareDeterministically) {
  TriangleMesh mesh;
  test::addSphere(mesh, Vec3(0, 0, 0), 1.0f, 64, 128, 0);  // ~16k triangles
  const float spacing = 0.05f;                             // ~0.3 surfels per triangle
  const SurfelSet s = sampleSurfelsUniform(mesh, whiteMaterial(), {spacing, 1.15f, 3});
  const double expected = test::meshArea(mesh) / (spacing * spacing);
  // Systematic rounding of the running sum: the total is exact up to one surfel.
  EXPECT_NEAR(static_cast<double>(s.size()), expected, 1.0);
  // Every triangle gets floor or ceil of its own expected count.
  std::vector<int> perTriangle(mesh.triangleCount(), 0);
  for (uint32_t t : s.triangle) ++perTriangle[t];
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    const double e = 0.5 *
                     length(cross(mesh.vertex(t, 1) - mesh.vertex(t, 0),
                                  mesh.vertex(t, 2) - mesh.vertex(t, 0))) /
                     (spacing * spacing);
    ASSERT_LE(std::abs(perTriangle[t] - e), 1.0) << "triangle " << t;
  }
}

TEST(SurfelSampler, SameSeedSameCloudOtherSeedOtherCloud) {
  TriangleMesh mesh;
  test::addBox(mesh, Vec3(0, 0, 0), Vec3(1, 1, 1), 0);
  test::addSphere(mesh, Vec3(0.5f, 0.5f, 0.5f), 0.3f, 16, 32, 0);
  const SurfelSet a = sampleSurfelsUniform(mesh, whiteMaterial(), {0.03f, 1.15f, 11});
  const SurfelSet b = sampleSurfelsUniform(mesh, whiteMaterial(), {0.03f, 1.15f, 11});
  const SurfelSet c = sampleSurfelsUniform(mesh, whiteMaterial(), {0.03f, 1.15f, 12});
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.position[i], b.position[i]);
    ASSERT_EQ(a.triangle[i], b.triangle[i]);
  }
  bool differs = a.size() != c.size();
  for (size_t i = 0; !differs && i < a.size(); ++i) differs = a.position[i] != c.position[i];
  EXPECT_TRUE(differs);
}

TEST(SurfelSampler, RejectsBadSpacingAndMissingMaterials) {
  TriangleMesh mesh;
  test::addQuad(mesh, Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0), 3);
  EXPECT_THROW(sampleSurfelsUniform(mesh, whiteMaterial(), {0.0f}), InputError);
  EXPECT_THROW(sampleSurfelsUniform(mesh, whiteMaterial(), {0.1f}), InputError);
}

TEST(SurfelSampler, CameraSurfelsCoverTheVisibleAreaOnce) {
  // A 4 x 4 quad at distance 5 seen by a camera whose view it fills and overflows:
  // the surfels stand for the part of the quad inside the widened frustum.
  TriangleMesh mesh;
  test::addQuad(mesh, Vec3(-2, -2, 0), Vec3(2, -2, 0), Vec3(2, 2, 0), Vec3(-2, 2, 0), 0);
  RayTracer tracer(mesh);
  Camera cam;
  cam.position = Vec3(0, 0, 5);
  cam.lookAt = Vec3(0, 0, 0);
  cam.vfovDeg = 30.0f;
  cam.width = 64;
  cam.height = 48;
  CameraSurfelSettings settings;
  settings.seed = 5;
  const SurfelSet s = sampleSurfelsFromCamera(tracer, whiteMaterial(), cam, settings);
  const float tanHalf = std::tan(0.5f * 30.0f * kPi / 180.0f);
  const double visibleH = 2.0 * 5.0 * tanHalf * 1.1, visibleW = visibleH * 64.0 / 48.0;
  EXPECT_EQ(s.size(), static_cast<size_t>(std::ceil(64 * 2 * 1.1) * std::ceil(48 * 2 * 1.1)));
  double area = 0.0;
  for (size_t i = 0; i < s.size(); ++i) {
    area += s.representedArea(i);
    ASSERT_NEAR(std::abs(s.normal[i].z), 1.0f, 1e-5f);
  }
  // Footprints tile the image plane: the represented area equals the visible area up to
  // the ceil() of the ray grid (< 1%) and the cos^3 approximation per ray (< 0.5%).
  std::printf("frontal quad: footprints / visible area = %.4f\n", area / (visibleW * visibleH));
  EXPECT_NEAR(area / (visibleW * visibleH), 1.0, 0.02);
  const SurfelSet again = sampleSurfelsFromCamera(tracer, whiteMaterial(), cam, settings);
  ASSERT_EQ(again.size(), s.size());
  for (size_t i = 0; i < s.size(); ++i) ASSERT_EQ(again.position[i], s.position[i]);
}

TEST(SurfelSampler, CameraFootprintsOnAnObliqueFloorAddUpToItsVisibleArea) {
  // Camera 2 above a large floor looking down at 40 degrees: the widened frustum's
  // footprint is the quadrilateral where its corner rays meet the floor. The footprints
  // (solid angle cos^3 * t^2 / cos theta) must add up to its area; 2%: the ceil() of the
  // ray grid and the per-ray linearisation of a footprint that grows across the image.
  TriangleMesh mesh;
  test::addQuad(mesh, Vec3(-50, 0, -50), Vec3(-50, 0, 50), Vec3(50, 0, 50), Vec3(50, 0, -50), 0);
  RayTracer tracer(mesh);
  Camera cam;
  cam.position = Vec3(0, 2, 0);
  cam.lookAt = Vec3(0, 2.0f - std::tan(40.0f * kPi / 180.0f), 1.0f);
  cam.vfovDeg = 20.0f;
  cam.width = 40;
  cam.height = 30;
  const SurfelSet s = sampleSurfelsFromCamera(tracer, whiteMaterial(), cam, {});
  double area = 0.0;
  for (size_t i = 0; i < s.size(); ++i) area += s.representedArea(i);
  // Corners of the ray grid: it spans [-0.05 W, 1.05 W] x [-0.05 H, 1.05 H] (rounded up).
  const float x1 = -0.05f * 40 + std::ceil(40 * 2 * 1.1f) / 2.0f;
  const float y1 = -0.05f * 30 + std::ceil(30 * 2 * 1.1f) / 2.0f;
  const float xs[4] = {-2.0f, x1, x1, -2.0f}, ys[4] = {-1.5f, -1.5f, y1, y1};
  double shoelace = 0.0;
  Vec3 q[4];
  for (int k = 0; k < 4; ++k) {
    const Ray r = cam.generateRay(xs[k], ys[k]);
    ASSERT_LT(r.dir.y, 0.0f);
    q[k] = r.at(-r.origin.y / r.dir.y);
  }
  for (int k = 0; k < 4; ++k) shoelace += q[k].x * q[(k + 1) % 4].z - q[(k + 1) % 4].x * q[k].z;
  std::printf("oblique floor: footprints / visible area = %.4f\n",
              area / (0.5 * std::abs(shoelace)));
  EXPECT_NEAR(area / (0.5 * std::abs(shoelace)), 1.0, 0.02);
}

}  // namespace
}  // namespace lvox
