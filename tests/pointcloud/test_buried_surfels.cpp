#include <gtest/gtest.h>

#include "pointcloud/buried_surfels.h"
#include "pointcloud/scenes.h"
#include "pointcloud/surfel_sampler.h"

namespace lvox {
namespace {

bool insideBox(const Vec3& p, const Vec3& lo, const Vec3& hi, float margin) {
  return p.x > lo.x + margin && p.y > lo.y + margin && p.z > lo.z + margin && p.x < hi.x - margin &&
         p.y < hi.y - margin && p.z < hi.z - margin;
}

TEST(BuriedSurfels, TheFacesInsideAnOverlappingSolidGoAndNothingElse) {
  // A slab pushed 0.15 into a wall, the way modelled scenes join pieces: the slab's faces
  // inside the wall and the wall's face inside the slab are buried. Every probe from a
  // point inside a box leaves it through one of its faces within reach 2 (the wall is
  // 1 x 1 x 0.3, the slab 0.6 x 0.1 x 0.65), so all of them go; every surfel outside both
  // boxes sees open space through some of its 16 strata, so none of those goes.
  const Vec3 wallLo(0, 0, 0), wallHi(1, 1, 0.3f), slabLo(0.2f, 0.4f, -0.5f),
      slabHi(0.8f, 0.5f, 0.15f);
  TriangleMesh mesh;
  test::addBox(mesh, wallLo, wallHi, 0);
  test::addBox(mesh, slabLo, slabHi, 0);
  SurfelSet s = sampleSurfelsUniform(mesh, {Material{}}, {0.02f, 1.15f, 3});
  RayTracer tracer(mesh);
  SurfelSet before = s;
  const size_t removed = removeBuriedSurfels(s, tracer, {2.0f, 16, 1});
  size_t buried = 0, kept = 0;
  for (size_t i = 0; i < before.size(); ++i) {
    const Vec3& p = before.position[i];
    const bool inside =
        insideBox(p, wallLo, wallHi, 0.005f) || insideBox(p, slabLo, slabHi, 0.005f);
    buried += inside;
  }
  for (size_t i = 0; i < s.size(); ++i) {
    const Vec3& p = s.position[i];
    ASSERT_FALSE(insideBox(p, wallLo, wallHi, 0.005f) || insideBox(p, slabLo, slabHi, 0.005f)) << p;
    ++kept;
  }
  // Surfels within 0.005 of the joint lines may go either way.
  const size_t outside = before.size() - buried;
  // Buried area: the slab's sides and end inside the wall (0.27) and the wall's face inside
  // the slab (0.06), 825 surfels at spacing 0.02 before the border sites.
  EXPECT_GT(buried, 800u);
  EXPECT_GE(removed, buried);
  EXPECT_LE(removed, buried + outside / 100);
  EXPECT_EQ(kept + removed, before.size());
  std::printf("buried %zu of %zu surfels, removed %zu\n", buried, before.size(), removed);
}

TEST(BuriedSurfels, OpenAndConcaveSurfacesKeepEverySurfel) {
  // A room without a ceiling (floor and four walls) and a free-standing box: every side of
  // every surfel sees the sky or the room through some probe.
  TriangleMesh mesh;
  test::addQuad(mesh, Vec3(0, 0, 0), Vec3(0, 0, 2), Vec3(2, 0, 2), Vec3(2, 0, 0), 0);
  test::addQuad(mesh, Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(2, 1, 0), Vec3(0, 1, 0), 0);
  test::addQuad(mesh, Vec3(0, 0, 2), Vec3(0, 1, 2), Vec3(2, 1, 2), Vec3(2, 0, 2), 0);
  test::addQuad(mesh, Vec3(0, 0, 0), Vec3(0, 1, 0), Vec3(0, 1, 2), Vec3(0, 0, 2), 0);
  test::addQuad(mesh, Vec3(2, 0, 0), Vec3(2, 0, 2), Vec3(2, 1, 2), Vec3(2, 1, 0), 0);
  test::addBox(mesh, Vec3(0.8f, 0.0f, 0.8f), Vec3(1.2f, 0.4f, 1.2f), 0);
  SurfelSet s = sampleSurfelsUniform(mesh, {Material{}}, {0.05f, 1.15f, 3});
  const size_t n = s.size();
  EXPECT_EQ(removeBuriedSurfels(s, RayTracer(mesh), {0.2f, 16, 1}), 0u);
  EXPECT_EQ(s.size(), n);
}

}  // namespace
}  // namespace lvox
