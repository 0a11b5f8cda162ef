// SphericalTriangle (src/core/spherical_triangle.h): solid angles against closed forms, and
// its samples inside the triangle and uniform over it. (Its use by the light set, pdfs
// included, is tested by chi-square in tests/render/test_light_sampling_chi_square.cpp.)
#include <gtest/gtest.h>

#include <cmath>

#include "src/core/math.h"
#include "src/core/rng.h"
#include "src/core/spherical_triangle.h"

namespace lvox {
namespace {

TEST(SphericalTriangle, SolidAnglesOfKnownTriangles) {
  // One octant of the sphere: pi / 2.
  EXPECT_NEAR(
      SphericalTriangle(Vec3(0.0f), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)).solidAngle(),
      kPi / 2.0, 1e-6);
  // Half of a unit square seen from height h above its corner: the square subtends
  // 4 asin(a b / sqrt((a^2 + 4 h^2)(b^2 + 4 h^2))) from above its centre, a quarter of
  // that from above a corner of a square twice as wide; its diagonal halves it.
  const double h = 0.37;
  const double quarter = std::asin(4.0 / (4.0 + 4.0 * h * h));  // 2 x 2 square, centre
  const Vec3 p(0.0f, 0.0f, static_cast<float>(h));
  EXPECT_NEAR(SphericalTriangle(p, Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0)).solidAngle(),
              0.5 * quarter, 1e-6);
  // Seen from its own plane, or degenerate: nothing.
  EXPECT_EQ(
      SphericalTriangle(Vec3(3, 0, 0), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0)).solidAngle(),
      0.0);
  // Tiny and far: about area cos / d^2.
  const double far =
      SphericalTriangle(Vec3(0, 0, 100), Vec3(0, 0, 0), Vec3(0.01f, 0, 0), Vec3(0, 0.01f, 0))
          .solidAngle();
  EXPECT_NEAR(far, 0.5e-4 / 1e4, 1e-3 * 0.5e-8);
}

// The share of samples in each of the 4 sub-triangles cut by the edge midpoints is its
// share of the solid angle (within 5 standard errors), and every sample lies inside.
TEST(SphericalTriangle, SamplesAreUniformOverTheSolidAngle) {
  const Vec3 p(0.1f, -0.2f, 0.05f);
  const Vec3 a(-1, -1, 0.6f), b(1.5f, -0.7f, 0.3f), c(0.2f, 1.2f, 0.9f);
  const SphericalTriangle whole(p, a, b, c);
  const Vec3 ab = (a + b) * 0.5f, bc = (b + c) * 0.5f, ca = (c + a) * 0.5f;
  const Vec3 parts[4][3] = {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}};
  const int n = 200000;
  int counts[4] = {0, 0, 0, 0};
  Rng rng(3, 0);
  for (int i = 0; i < n; ++i) {
    const Vec3 w = whole.sample(rng.uniform(), rng.uniform());
    ASSERT_NEAR(length(w), 1.0f, 1e-5f);
    // Which sub-triangle the ray p + t w crosses (the plane of a, b, c holds all four).
    const Vec3 nrm = cross(b - a, c - a);
    const float t = dot(a - p, nrm) / dot(w, nrm);
    ASSERT_GT(t, 0.0f);
    const Vec3 q = p + w * t;
    int inside = -1;
    for (int k = 0; k < 4; ++k) {
      const Vec3& u = parts[k][0];
      const Vec3& v = parts[k][1];
      const Vec3& x = parts[k][2];
      const float s1 = dot(cross(v - u, q - u), nrm), s2 = dot(cross(x - v, q - v), nrm),
                  s3 = dot(cross(u - x, q - x), nrm);
      if (s1 >= 0.0f && s2 >= 0.0f && s3 >= 0.0f) inside = k;
    }
    ASSERT_GE(inside, 0) << "a sample outside the triangle";
    ++counts[inside];
  }
  for (int k = 0; k < 4; ++k) {
    const double share = SphericalTriangle(p, parts[k][0], parts[k][1], parts[k][2]).solidAngle() /
                         whole.solidAngle();
    const double se = std::sqrt(share * (1.0 - share) / n);
    EXPECT_NEAR(counts[k] / double(n), share, 5.0 * se) << "sub-triangle " << k;
  }
}

}  // namespace
}  // namespace lvox
