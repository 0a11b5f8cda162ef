#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "pointcloud/light_cache.h"
#include "pointcloud/lvoxel_sampler.h"
#include "pointcloud/ray_directions.h"
#include "pointcloud/scenes.h"
#include "pointcloud/surfel_sampler.h"

namespace lvox {
namespace {

// Closed unit box of surfels (spacing 0.02, ~15000 surfels) with radiance 1 on both
// sides, cached through cacheDirectLight.
PointCloud furnaceBox(const LvoxelSet& lvoxels = {}, float spacing = 0.02f) {
  TriangleMesh mesh;
  test::addBox(mesh, Vec3(0, 0, 0), Vec3(1, 1, 1), 0);
  SurfelSet s = sampleSurfelsUniform(mesh, {Material{}}, {spacing, 1.15f, 9});
  PointCloud pc(std::move(s), lvoxels);
  cacheDirectLight(
      pc, [](const SurfelLightQuery&) { return RGB(1.0f); },
      [](const LvoxelLightQuery&) { return RGB(0.0f); });
  return pc;
}

TEST(Gather, ClosedBoxOfUniformRadianceGathersOne) {
  // Furnace test: every gather ray must hit a disk of radiance 1, so E / pi = 1 minus
  // the solid angle of holes. Hexagonal-lattice disks cover each face; only strips at
  // the box edges can be open. 2% tolerance: the brief's bound for the cloud.
  const PointCloud pc = furnaceBox();
  GatherOptions o;
  o.samples = 256;
  const Vec3 points[] = {{0.5f, 0.5f, 0.5f}, {0.2f, 0.7f, 0.3f}, {0.9f, 0.1f, 0.15f}};
  const Vec3 normals[] = {{0, 1, 0}, {1, 0, 0}, normalize(Vec3(1, -1, 2))};
  Rng rng(1, 1);
  float worst = 0.0f;
  for (const Vec3& p : points)
    for (const Vec3& n : normals) {
      const RGB e = gatherIrradiance(pc, p, n, o, rng);
      EXPECT_NEAR(e.x / kPi, 1.0f, 0.02f) << p << " " << n;
      worst = std::max(worst, std::abs(e.x / kPi - 1.0f));
    }
  // On the floor itself, looking up: the receiver's own disks must not shadow it.
  const RGB floor = gatherIrradiance(pc, Vec3(0.37f, 0.0f, 0.61f), Vec3(0, 1, 0), o, rng);
  EXPECT_NEAR(floor.y / kPi, 1.0f, 0.02f);
  std::printf("furnace: worst interior |E/pi - 1| = %.4f, on the floor %.4f\n", worst,
              floor.y / kPi);
}

TEST(Gather, CoarseLatticesCloseTheFurnaceAtTheBoxEdges) {
  // 3-5 surfels across a face: the disks along the borders must still close the box.
  // Every ray hits radiance 1 unless it finds a hole, so there is no noise to allow for;
  // before border sites, holes along the edges lost 4.2-5.4 %.
  GatherOptions o;
  o.samples = 1024;
  const Vec3 points[] = {{0.5f, 0.5f, 0.5f}, {0.2f, 0.7f, 0.3f}, {0.9f, 0.1f, 0.15f}};
  const Vec3 normals[] = {{0, 1, 0}, {1, 0, 0}, normalize(Vec3(1, -1, 2))};
  for (float spacing : {0.2f, 0.25f, 0.33f}) {
    const PointCloud pc = furnaceBox({}, spacing);
    Rng rng(3, 1);
    float worst = 0.0f;
    for (const Vec3& p : points)
      for (const Vec3& n : normals)
        worst = std::max(worst, std::abs(gatherIrradiance(pc, p, n, o, rng).x / kPi - 1.0f));
    std::printf("furnace at spacing %.2f (%zu surfels): worst |E/pi - 1| = %.4f\n", spacing,
                pc.surfels().size(), worst);
    EXPECT_LT(worst, 1e-3f) << "spacing " << spacing;
  }
}

TEST(Gather, ClustersKeepTheFurnaceWithinThreePercent) {
  // With the level of detail on (max solid angle 0.03 sr, the prior-art default), distant
  // faces are seen as partly covering boxes (SurfelCluster): the coverage error of the
  // approximation stays within 3% (measured 0.95%), with less traversal work.
  const PointCloud pc = furnaceBox();
  GatherOptions exact, lod;
  exact.samples = lod.samples = 256;
  lod.maxSolidAngle = 0.03f;
  Rng rngA(2, 1), rngB(2, 1);
  TraversalScratch sa, sb;
  const RGB a = gatherIrradiance(pc, Vec3(0.5f, 0.05f, 0.5f), Vec3(0, 1, 0), exact, rngA, sa);
  const RGB b = gatherIrradiance(pc, Vec3(0.5f, 0.05f, 0.5f), Vec3(0, 1, 0), lod, rngB, sb);
  EXPECT_NEAR(a.x / kPi, 1.0f, 0.02f);
  EXPECT_NEAR(b.x / kPi, 1.0f, 0.03f);
  std::printf("furnace exact %.4f, clusters %.4f; work %llu vs %llu\n", a.x / kPi, b.x / kPi,
              static_cast<unsigned long long>(sa.stats.elementsTested + sa.stats.nodesPopped),
              static_cast<unsigned long long>(sb.stats.elementsTested + sb.stats.nodesPopped));
  // Less traversal work (nodes popped + elements tested): 2587 vs 4569 when measured;
  // clusters pay off more in large scenes (see the benchmark).
  EXPECT_LT(sb.stats.elementsTested + sb.stats.nodesPopped,
            sa.stats.elementsTested + sa.stats.nodesPopped);
}

// Irradiance at the origin (normal +y) from a Lambertian rectangle x = a, y in [0, h],
// z in [-w/2, w/2] of radiance 1: E = integral cos(theta) cos(theta') / r^2 dA,
// midpoint rule in double on a fine grid (the integrand is smooth).
double rectangleIrradiance(double a, double h, double w) {
  const int n = 600;
  double e = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double y = (i + 0.5) * h / n, z = -0.5 * w + (j + 0.5) * w / n;
      const double r2 = a * a + y * y + z * z;
      e += (y / std::sqrt(r2)) * (a / std::sqrt(r2)) / r2;
    }
  return e * (h / n) * (w / n);
}

TEST(Gather, WhiteFloorBesideRedWallReceivesRedLight) {
  // Floor y = 0 (white, radiance 0.5) and a red wall x = 0.5 (radiance (0.6, 0.03, 0.03)),
  // 1 high, 2 wide. The floor point at the origin sees only the wall (the floor is in its
  // tangent plane), so E = L_wall * E_unit with E_unit the analytic irradiance from a
  // unit-radiance rectangle.
  TriangleMesh mesh;
  test::addQuad(mesh, Vec3(-1, 0, -1), Vec3(-1, 0, 1), Vec3(0.5f, 0, 1), Vec3(0.5f, 0, -1), 0);
  test::addQuad(mesh, Vec3(0.5f, 0, -1), Vec3(0.5f, 0, 1), Vec3(0.5f, 1, 1), Vec3(0.5f, 1, -1), 1);
  const std::vector<Material> materials = {Material{"white", RGB(0.8f), RGB(0.0f)},
                                           Material{"red", RGB(0.8f, 0.04f, 0.04f), RGB(0.0f)}};
  PointCloud pc(sampleSurfelsUniform(mesh, materials, {0.01f, 1.15f, 4}), LvoxelSet{});
  const RGB wallRadiance(0.6f, 0.03f, 0.03f);
  cacheDirectLight(
      pc,
      [&](const SurfelLightQuery& q) {
        return std::abs(q.normal.x) > 0.5f ? wallRadiance : RGB(0.5f);  // both sides alike
      },
      [](const LvoxelLightQuery&) { return RGB(0.0f); });
  const double unit = rectangleIrradiance(0.5, 1.0, 2.0);
  GatherOptions o;
  o.samples = 256;
  RGB sum(0.0f);
  const int gathers = 16;  // 4096 stratified rays: relative noise well below 1%
  for (int g = 0; g < gathers; ++g) {
    Rng rng(7, static_cast<uint64_t>(g));
    sum += gatherIrradiance(pc, Vec3(0, 0, 0), Vec3(0, 1, 0), o, rng);
  }
  const RGB e = sum / static_cast<float>(gathers);
  std::printf("red wall: gathered E = (%.4f %.4f %.4f), analytic (%.4f %.4f %.4f)\n", e.x, e.y, e.z,
              wallRadiance.x * unit, wallRadiance.y * unit, wallRadiance.z * unit);
  EXPECT_GT(e.x, 10.0f * e.y);
  EXPECT_GT(e.x, 10.0f * e.z);
  // 3% (the brief asks for 10%): disks (radius 0.65 spacing) overhang the wall's three
  // free edges, adding up to 0.65 * 0.01 * 4 / 2 = 1.3% of its area; the stratified noise
  // of 4096 rays is below 0.5%. Measured: +0.9%.
  EXPECT_NEAR(e.x / (wallRadiance.x * unit), 1.0, 0.03);
  EXPECT_NEAR(e.y / (wallRadiance.y * unit), 1.0, 0.03);
  // Outgoing colour-bleeding radiance of the white floor: albedo * E / pi.
  const RGB bleed = RGB(0.8f) * e / kPi;
  EXPECT_GT(bleed.x, 0.0f);
}

// The furnace box filled with a purely absorbing medium (sigma_a = 1.5, lvoxel spacing
// 1/16).
PointCloud absorberBox() {
  const test::BoxMedium medium(Vec3(0, 0, 0), Vec3(1, 1, 1), RGB(1.5f), RGB(0.0f));
  return furnaceBox(sampleLvoxels(medium, {0.0625f}));
}

// Its isotropic in-scatter at p: the mean over the sphere of exp(-sigma_a * d(p, w)), d the
// distance to the wall, by midpoint quadrature over 400 x 400 directions.
double absorberInScatter(const Vec3& p) {
  double sum = 0.0;
  const int n = 400;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Vec3 w =
          uniformSphere((static_cast<float>(i) + 0.5f) / n, (static_cast<float>(j) + 0.5f) / n);
      float t0, t1;
      Bounds3 box;
      box.lo = Vec3(0, 0, 0);
      box.hi = Vec3(1, 1, 1);
      box.intersect(Ray{p, w, 0.0f, kInf}, t0, t1);
      sum += std::exp(-1.5 * t1);
    }
  return sum / (n * n);
}

// The isotropic in-scatter at p in the absorber box, averaged over four gathers of
// independent rays, over its quadrature.
double absorberInScatterRatio(const Vec3& p, const GatherOptions& o, const char* what) {
  const PointCloud pc = absorberBox();
  double sum = 0.0;
  for (int g = 0; g < 4; ++g) {
    Rng rng(5, static_cast<uint64_t>(g));
    sum += gatherInScatter(pc, p, Vec3(0, 0, 1), IsotropicPhase{}, o, rng).x;
  }
  const double expected = absorberInScatter(p);
  std::printf("in-scatter %s: %.4f, quadrature %.4f\n", what, sum / 4.0, expected);
  return sum / 4.0 / expected;
}

TEST(Gather, InScatterThroughAbsorbingMediumInAClosedBox) {
  // Unit box of surfels of radiance 1, filled with a purely absorbing medium
  // (sigma_a = 1.5, lvoxel spacing 1/16). Isotropic in-scatter at p is the mean over the
  // sphere of exp(-sigma_a * d(p, w)), d the distance to the wall: computed here by
  // quadrature over directions. 2%: the stratified estimate of 256 rays is smooth.
  GatherOptions o;
  o.samples = 256;
  EXPECT_NEAR(absorberInScatterRatio(Vec3(0.4f, 0.55f, 0.47f), o, "through absorber"), 1.0, 0.02);
}

TEST(Gather, NearFieldRaysKeepTheInScatterThroughAnAbsorber) {
  // The absorber box above, with each stratum's near field (within 0.3 of p: a wall is
  // that close in some directions, the lvoxels in all of them) sampled by four rays
  // instead of one: the same integral, the same quadrature, the same 2 %.
  GatherOptions o;
  o.samples = 64;
  o.nearSamples = 256;
  o.nearReach = 0.3f;
  ASSERT_EQ(nearFieldRaysPerRay(o), 3);
  EXPECT_NEAR(absorberInScatterRatio(Vec3(0.25f, 0.55f, 0.47f), o, "with a near field"), 1.0, 0.02);
}

// Records the weight a gather ray gives each lvoxel.
struct LvoxelWeights {
  std::vector<float> weight;
  explicit LvoxelWeights(size_t n) : weight(n, 0.0f) {}
  void beginRay(const Vec3&) {}
  void surfel(uint32_t, bool, const RGB&) {}
  void surfelCluster(uint32_t, const RGB&) {}
  void lvoxel(uint32_t i, const RGB& w) { weight[i] += w.x; }
  void lvoxelCluster(uint32_t, const RGB&) {}
  void addBackground(const RGB&) {}
  void surfaceLight(const RGB&) {}
};

TEST(Gather, FourQuartersStratifyTheHemisphereFourTimesAsFinely) {
  // 64 rays in 8 x 8 strata of the cosine map (u1 = 1 - cos^2, u2 = azimuth / 2 pi).
  // Alone, a gather with quarter q has one ray per stratum, in that stratum's quarter q;
  // the four quarters together have one ray in each of the 16 x 16 half-strata (the final
  // gathers' grid gives a 2 x 2 block of points the four quarters).
  const PointCloud pc(SurfelSet{}, LvoxelSet{});
  TraversalScratch scratch;
  std::vector<int> fine(16 * 16, 0);
  for (int q = 0; q < 4; ++q) {
    GatherOptions o;
    o.samples = 64;
    o.quarter = q;
    test::RayDirections sink;
    Rng rng(7, static_cast<uint64_t>(q));
    gatherIrradianceInto(pc, Vec3(0.0f), Vec3(0, 0, 1), o, rng, scratch, sink);
    ASSERT_EQ(sink.dirs.size(), 64u);
    std::vector<int> coarse(8 * 8, 0);
    for (const Vec3& d : sink.dirs) {
      const auto [u1, u2] = test::cosineMapPoint(d);
      const int f1 = std::min(15, static_cast<int>(u1 * 16.0f));
      const int f2 = std::min(15, static_cast<int>(u2 * 16.0f));
      ++coarse[static_cast<size_t>((f1 / 2) * 8 + f2 / 2)];
      ++fine[static_cast<size_t>(f1 * 16 + f2)];
      EXPECT_EQ(f1 % 2, q & 1) << q;
      EXPECT_EQ(f2 % 2, (q >> 1) & 1) << q;
    }
    for (int c : coarse) EXPECT_EQ(c, 1) << q;
  }
  for (int c : fine) EXPECT_EQ(c, 1);
}

TEST(Gather, NearFieldSplitsTheCubeAtItsEndExactly) {
  // A ray through a slab of lvoxels (sigma_t 2, cubes 0.25). Its near field ends inside a
  // cube: with share 1 the two parts of that cube add up to its whole weight, and with
  // share s the lvoxels before the end get s of what a ray cut there gives them, those
  // beyond what the whole ray gives them.
  const test::BoxMedium slab(Vec3(-1, -1, 0), Vec3(1, 1, 2), RGB(1.0f), RGB(1.0f));
  const PointCloud pc(SurfelSet{}, sampleLvoxels(slab, {0.25f}));
  const size_t n = pc.lvoxels().size();
  GatherOptions o;
  TraversalScratch scratch;
  const Ray ray{Vec3(0.1f, 0.05f, -0.5f), normalize(Vec3(0.1f, 0.2f, 1.0f)), 0.0f, kInf};
  const float end = 1.13f;  // 0.63 into the slab: inside its third cube
  LvoxelWeights whole(n), split(n), cut(n), shared(n);
  traceGatherRay(pc, ray, o, 1.0f, scratch, whole);
  traceGatherRay(pc, ray, o, 1.0f, scratch, split, NearField{end, 1.0f});
  traceGatherRay(pc, Ray{ray.origin, ray.dir, 0.0f, end}, o, 1.0f, scratch, cut);
  traceGatherRay(pc, ray, o, 1.0f, scratch, shared, NearField{end, 0.25f});
  int before = 0, across = 0;
  for (size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(split.weight[i], whole.weight[i], 1e-6f) << i;
    // The part beyond the end: what the whole ray gives, less what the cut ray does.
    const float far = whole.weight[i] - cut.weight[i];
    EXPECT_NEAR(shared.weight[i], 0.25f * cut.weight[i] + far, 1e-6f) << i;
    before += cut.weight[i] > 0.0f;
    across += cut.weight[i] > 0.0f && far > 1e-4f;
  }
  EXPECT_GE(before, 3);
  EXPECT_EQ(across, 1);  // the cube the end falls in
}

TEST(Gather, WallSeenThroughAGlowingSlab) {
  // A wall of radiance 1 (z = 1) behind a slab z in [0.25, 0.75] with sigma_a = sigma_s =
  // 0.5 whose cached in-scatter is 0.4: source radiance J = 0.5 * 0.4 = 0.2 and the RTE
  // gives L = T + J (1 - T), T = exp(-sigma_t * 0.5 / cos theta), along every ray.
  TriangleMesh mesh;
  test::addQuad(mesh, Vec3(-3, -3, 1), Vec3(3, -3, 1), Vec3(3, 3, 1), Vec3(-3, 3, 1), 0);
  const test::BoxMedium slab(Vec3(-3, -3, 0.25f), Vec3(3, 3, 0.75f), RGB(0.5f), RGB(0.5f));
  LvoxelSettings ls;
  ls.spacing = 0.125f;
  PointCloud pc(sampleSurfelsUniform(mesh, {Material{}}, {0.05f, 1.15f, 2}),
                sampleLvoxels(slab, ls));
  cacheDirectLight(
      pc, [](const SurfelLightQuery&) { return RGB(1.0f); },
      [](const LvoxelLightQuery&) { return RGB(0.4f); });
  TraversalScratch scratch;
  for (float theta : {0.0f, 25.0f, 50.0f}) {
    const float th = theta * kPi / 180.0f;
    const Ray ray{Vec3(0.03f, -0.02f, 0.0f), Vec3(std::sin(th), 0.0f, std::cos(th)), 1e-4f, kInf};
    const RGB l = gatherRay(pc, ray, GatherOptions{}, scratch);
    const float t = std::exp(-1.0f * 0.5f / std::cos(th));
    EXPECT_NEAR(l.x, t + 0.2f * (1.0f - t), 1e-4f) << theta;
  }
}

TEST(Gather, MultipleScatteringCacheFillsLvoxels) {
  // Lvoxels in the furnace box with albedo 1 and no direct light: one bounce gathers the
  // walls' radiance 1 attenuated by the medium plus nothing else, so 0 < L_s < 1; a second
  // bounce adds the medium's own scattered light and can only increase it.
  const test::BoxMedium medium(Vec3(0.25f, 0.25f, 0.25f), Vec3(0.75f, 0.75f, 0.75f), RGB(0.0f),
                               RGB(4.0f));
  PointCloud pc = furnaceBox(sampleLvoxels(medium, {0.125f}));
  GatherOptions o;
  o.samples = 64;
  cacheMultipleScattering(pc, IsotropicPhase{}, o, 1, 3);
  const LvoxelLight& light = pc.lvoxels().light;
  std::vector<RGB> one;
  for (uint32_t s = 0; s < light.occupiedCount(); ++s) one.push_back(light.multiScatter(s)[0]);
  cacheMultipleScattering(pc, IsotropicPhase{}, o, 2, 3);
  ASSERT_GT(one.size(), 0u);
  for (uint32_t s = 0; s < one.size(); ++s) {
    EXPECT_GT(one[s].x, 0.2f);
    EXPECT_LT(one[s].x, 1.0f);
    EXPECT_GE(light.multiScatter(s)[0].x, one[s].x - 1e-5f);
    // Non-absorbing medium inside walls of radiance 1: the fixed point is 1.
    EXPECT_LE(light.multiScatter(s)[0].x, 1.0f + 1e-4f);
  }
}

}  // namespace
}  // namespace lvox
