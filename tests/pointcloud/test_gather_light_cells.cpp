// The lit surfaces' cells of the final gathers (pointcloud/gather_light_cells.h) and the
// gathers that aim a share of their rays at them (gather.h, multiple importance sampling).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "chi_square.h"
#include "pointcloud/gather.h"
#include "pointcloud/gather_light_cells.h"
#include "pointcloud/light_cache.h"
#include "pointcloud/lvoxel_sampler.h"
#include "pointcloud/scenes.h"
#include "pointcloud/surfel_lookup.h"
#include "pointcloud/surfel_sampler.h"
#include "src/geometry/ray_tracer.h"

namespace lvox {
namespace {

// A square of the ceiling (y = 1) lit by a "delta light" that the surfels leave to the hits
// (as DeltaHitLight): radiance 40 below x, z < 0.2 and nothing elsewhere. A small bright
// spot, the final gathers' worst case.
struct SpotHitLight final : SurfaceHitLight {
  static bool inSpot(const Vec3& p, const Vec3& n) {
    return p.y > 0.999f && n.y < 0.0f && p.x < 0.2f && p.z < 0.2f;
  }
  RGB reflected(const SurfaceHit& hit) const override {
    return inSpot(hit.point, hit.normal) ? RGB(40.0f) : RGB(0.0f);
  }
  RGB reflected(const Vec3& p, const Vec3& n, const RGB& albedo) const override {
    return inSpot(p, n) ? albedo * 40.0f : RGB(0.0f);
  }
};

// The closed unit box: its surfels send 0.1 from their inside, 0.3 from the floor's
// corner x, z > 0.7, and the spot lights the ceiling's corner. Optionally a glowing,
// absorbing slab crosses it at y in [0.4, 0.6].
struct SpotBox {
  TriangleMesh mesh;
  RayTracer tracer;
  PointCloud cloud;
  SurfelLookup lookup;
  SpotHitLight spot;

  static TriangleMesh makeMesh() {
    TriangleMesh m;
    test::addBox(m, Vec3(0, 0, 0), Vec3(1, 1, 1), 0);
    return m;
  }
  static LvoxelSet slab(bool withSlab) {
    if (!withSlab) return {};
    const test::BoxMedium medium(Vec3(0, 0.4f, 0), Vec3(1, 0.6f, 1), RGB(1.0f), RGB(1.0f));
    LvoxelSettings ls;
    ls.spacing = 0.1f;
    return sampleLvoxels(medium, ls);
  }
  explicit SpotBox(bool withSlab = false)
      : mesh(makeMesh()),
        tracer(mesh),
        cloud(sampleSurfelsUniform(mesh, {Material{}}, {0.05f, 1.15f, 3}), slab(withSlab)),
        lookup(cloud.surfels(), 0.05f) {
    cacheDirectLight(
        cloud,
        [](const SurfelLightQuery& q) {
          const bool inside = dot(q.normal, Vec3(0.5f) - q.position) > 0.0f;
          const bool corner = q.position.y < 1e-3f && q.position.x > 0.7f && q.position.z > 0.7f;
          return RGB(inside ? (corner ? 0.3f : 0.1f) : 0.0f);
        },
        [](const LvoxelLightQuery&) { return RGB(0.5f); });
  }
  GatherOptions options(int samples, int lightSamples, const GatherLightCells* cells) const {
    GatherOptions o;
    o.samples = samples;
    o.tracer = &tracer;
    o.lookup = &lookup;
    o.hitLight = &spot;
    o.lights = cells;
    o.lightSamples = lightSamples;
    return o;
  }
};

TEST(GatherLightCells, LightsAreDrawnWithTheDensityTheyClaim) {
  // Pearson's test over the cells of each triangle split once more (each cell of m
  // divisions holds four of 2 m), for each side: the regions' weights for a receiver, the
  // light's choice by power in its region and the uniform point in the cell together,
  // against pdfArea integrated over each bin, at two receivers. Every sample's own density
  // must be the one pdfArea gives at its barycentrics.
  const SpotBox box;
  const float step = 0.2f;
  const GatherLightCells cells(box.mesh, box.cloud, box.options(1, 0, nullptr), step);
  ASSERT_FALSE(cells.empty());
  EXPECT_GT(cells.regions(), 12u);  // the box's twelve triangles' lights, split further
  std::vector<uint32_t> firstBin(box.mesh.triangleCount() + 1, 0);
  std::vector<uint32_t> divisions(box.mesh.triangleCount());
  std::vector<Vec3> faceNormal(box.mesh.triangleCount());
  for (size_t t = 0; t < box.mesh.triangleCount(); ++t) {
    const Vec3 a = box.mesh.vertex(t, 0), b = box.mesh.vertex(t, 1), c = box.mesh.vertex(t, 2);
    divisions[t] = GatherLightCells::divisionsOf(a, b, c, step);
    faceNormal[t] = normalize(cross(b - a, c - a));
    firstBin[t + 1] = firstBin[t] + 2 * 4 * divisions[t] * divisions[t];
  }
  EXPECT_EQ(cells.cells(), firstBin.back() / 8);
  const Vec3 receivers[][2] = {{{0.5f, 0.0f, 0.5f}, {0, 1, 0}}, {{0.3f, 0.6f, 1.0f}, {0, 0, -1}}};
  for (const auto& [p, n] : receivers) {
    const GatherLightCells::View view = cells.view(p, n);
    ASSERT_FALSE(view.empty());
    std::vector<double> observed(firstBin.back(), 0.0), expected(firstBin.back(), 0.0);
    Rng rng(11, 3);
    const int samples = 400000;
    size_t mismatched = 0;
    for (int k = 0; k < samples; ++k) {
      const GatherLightCells::Sample s =
          cells.sample(view, rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform());
      ASSERT_LT(s.triangle, box.mesh.triangleCount());
      ASSERT_GE(s.b1, -1e-6f);
      ASSERT_GE(s.b2, -1e-6f);
      ASSERT_LE(s.b1 + s.b2, 1.0f + 1e-5f);
      // Only lit sides facing the receiver's half space are drawn for it.
      const float q = cells.pdfArea(view, s.triangle, s.b1, s.b2, s.normal);
      mismatched += std::abs(q - s.pdfArea) > 1e-5f * s.pdfArea;
      const uint32_t m = divisions[s.triangle];
      const uint32_t side = dot(s.normal, faceNormal[s.triangle]) > 0.0f ? 0 : 1;
      observed[firstBin[s.triangle] + 2 * GatherLightCells::cellOf(2 * m, s.b1, s.b2) + side] +=
          1.0;
    }
    // A point on a cell's edge may fall in the neighbour's cell by rounding: rarely.
    EXPECT_LE(mismatched, static_cast<size_t>(samples / 10000));
    for (size_t t = 0; t < box.mesh.triangleCount(); ++t) {
      const Vec3 a = box.mesh.vertex(t, 0);
      const float area = 0.5f * length(cross(box.mesh.vertex(t, 1) - a, box.mesh.vertex(t, 2) - a));
      const uint32_t m2 = 2 * divisions[t];
      // Each bin's density, at its centre (bins lie inside one cell), times its area.
      for (uint32_t i = 0; i < m2; ++i)
        for (uint32_t j = 0; i + j < m2; ++j)
          for (uint32_t upper = 0; upper < 2 && i + j + upper < m2; ++upper)
            for (uint32_t side = 0; side < 2; ++side) {
              const float c = upper ? 2.0f / 3.0f : 1.0f / 3.0f;
              const float b1 = (static_cast<float>(i) + c) / static_cast<float>(m2);
              const float b2 = (static_cast<float>(j) + c) / static_cast<float>(m2);
              const uint32_t bin = firstBin[t] + 2 * GatherLightCells::cellOf(m2, b1, b2) + side;
              const Vec3 towards = side == 0 ? faceNormal[t] : -faceNormal[t];
              expected[bin] = samples *
                              static_cast<double>(
                                  cells.pdfArea(view, static_cast<uint32_t>(t), b1, b2, towards)) *
                              area / (static_cast<double>(m2) * m2);
            }
    }
    double total = 0.0;
    for (double e : expected) total += e;
    EXPECT_NEAR(total / samples, 1.0, 1e-4);  // the density integrates to one
    const test::ChiSquareResult r = test::chiSquareTest(observed, expected);
    EXPECT_TRUE(r.accepted()) << r.describe();
  }
  // From the floor's middle, the spot's cells (1 % of the box's inner area, about 70 % of
  // its power) take 39 % of the draws: their regions hold dimmer ceiling too.
  const GatherLightCells::View floor = cells.view(Vec3(0.5f, 0.0f, 0.5f), Vec3(0, 1, 0));
  Rng rng(4, 4);
  double spot = 0.0;
  const int draws = 10000;
  for (int k = 0; k < draws; ++k) {
    const GatherLightCells::Sample s =
        cells.sample(floor, rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform());
    spot += SpotHitLight::inSpot(s.point, s.normal);
  }
  EXPECT_GT(spot / draws, 0.3);
}

// Mean and variance of E / pi over `runs` gathers at p.
struct Moments {
  double mean = 0.0, variance = 0.0;
};
Moments gatherMoments(const PointCloud& cloud, const Vec3& p, const Vec3& n, const GatherOptions& o,
                      int runs) {
  double sum = 0.0, sum2 = 0.0;
  TraversalScratch scratch;
  for (int k = 0; k < runs; ++k) {
    Rng rng(5, static_cast<uint64_t>(k));
    const double e = gatherIrradiance(cloud, p, n, o, rng, scratch).x / kPi;
    sum += e;
    sum2 += e * e;
  }
  const double mean = sum / runs;
  return {mean, (sum2 / runs - mean * mean) * runs / (runs - 1)};
}

// (1 / pi) * integral of cos over the solid angle of a convex polygon seen from p with
// normal n, every vertex above the plane (Lambert's formula: the sum over the edges of
// their angle times the cosine of their plane's normal with n, over 2 pi).
double polygonFormFactor(const Vec3& p, const Vec3& n, const std::vector<Vec3>& polygon) {
  double sum = 0.0;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Vec3 a = normalize(polygon[i] - p), b = normalize(polygon[(i + 1) % polygon.size()] - p);
    const Vec3 c = cross(a, b);
    sum += std::acos(std::clamp(static_cast<double>(dot(a, b)), -1.0, 1.0)) *
           static_cast<double>(dot(n, c)) / static_cast<double>(length(c));
  }
  return std::abs(sum) / (2.0 * kPi);
}

TEST(GatherLightCells, GathersKeepTheirMeanAndLoseMostOfTheSpotsNoise) {
  // 16 of 64 rays at the cells against 64 cosine rays, at three receivers, with and
  // without a glowing slab between the floor and the spot (whose light only the cosine
  // rays bring, and which dims what the cells' rays reach): the same mean within four
  // standard errors of the difference, and at most half the variance. Without the slab the
  // exact E / pi is known: 0.1 from the whole box, 40 times the spot's form factor and
  // 0.2 times the floor corner's; the cells' gathers must find it within four of their
  // standard errors and 0.001 (where the corner's surfels stand for the walls beside it).
  const std::vector<Vec3> spot = {{0, 1, 0}, {0.2f, 1, 0}, {0.2f, 1, 0.2f}, {0, 1, 0.2f}};
  const std::vector<Vec3> corner = {{0.7f, 0, 0.7f}, {1, 0, 0.7f}, {1, 0, 1}, {0.7f, 0, 1}};
  for (bool withSlab : {false, true}) {
    const SpotBox box(withSlab);
    const GatherLightCells cells(box.mesh, box.cloud, box.options(1, 0, nullptr), 0.1f);
    const Vec3 points[] = {{0.5f, 0.0f, 0.5f}, {0.1f, 0.0f, 0.85f}, {0.8f, 0.3f, 0.0f}};
    const Vec3 normals[] = {{0, 1, 0}, {0, 1, 0}, {0, 0, 1}};
    const int runs = 1500;
    for (int i = 0; i < 3; ++i) {
      if (!withSlab) {
        const double exact =
            0.1 + 40.0 * polygonFormFactor(points[i], normals[i], spot) +
            (i == 2 ? 0.2 * polygonFormFactor(points[i], normals[i], corner) : 0.0);
        const Moments mis =
            gatherMoments(box.cloud, points[i], normals[i], box.options(64, 16, &cells), runs);
        EXPECT_NEAR(mis.mean, exact, 4.0 * std::sqrt(mis.variance / runs) + 1e-3) << i;
      }
      const Moments cosine =
          gatherMoments(box.cloud, points[i], normals[i], box.options(64, 0, &cells), runs);
      const Moments mis =
          gatherMoments(box.cloud, points[i], normals[i], box.options(64, 16, &cells), runs);
      const double error = std::sqrt((cosine.variance + mis.variance) / runs);
      std::printf(
          "slab %d, receiver %d: E/pi %.5f +- %.5f (cosine), %.5f +- %.5f (cells), "
          "variance ratio %.3f\n",
          withSlab, i, cosine.mean, std::sqrt(cosine.variance / runs), mis.mean,
          std::sqrt(mis.variance / runs), mis.variance / cosine.variance);
      EXPECT_NEAR(mis.mean, cosine.mean, 4.0 * error) << withSlab << " " << i;
      EXPECT_LT(mis.variance, 0.5 * cosine.variance) << withSlab << " " << i;
      EXPECT_GT(mis.mean, 0.05) << withSlab << " " << i;  // the spot is seen
    }
  }
}

TEST(GatherLightCells, WithoutTracedVisibilityOrLightTheGathersSendOnlyCosineRays) {
  // Gibson's disk visibility has no triangle to weigh a ray's surface by, and cells
  // without power have nothing to aim at: the gather is the cosine rays', bit for bit.
  const SpotBox box;
  const GatherLightCells cells(box.mesh, box.cloud, box.options(1, 0, nullptr), 0.1f);
  GatherOptions disks = box.options(64, 16, &cells);
  disks.tracer = nullptr;
  disks.lookup = nullptr;
  EXPECT_EQ(lightRaysOf(disks), 0);
  const GatherLightCells none;
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(lightRaysOf(box.options(64, 16, &none)), 0);
  EXPECT_EQ(lightRaysOf(box.options(64, 16, &cells)), 16);
  EXPECT_EQ(lightRaysOf(box.options(4, 16, &cells)), 3);  // one cosine ray stays
  Rng a(1, 2), b(1, 2);
  const RGB withCells = gatherIrradiance(box.cloud, Vec3(0.5f, 0, 0.5f), Vec3(0, 1, 0),
                                         box.options(64, 16, &none), a);
  const RGB without = gatherIrradiance(box.cloud, Vec3(0.5f, 0, 0.5f), Vec3(0, 1, 0),
                                       box.options(64, 0, nullptr), b);
  EXPECT_EQ(withCells.x, without.x);
}

}  // namespace
}  // namespace lvox
