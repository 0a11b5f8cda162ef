#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numeric>

#include "pointcloud/light_cache.h"
#include "pointcloud/ray_directions.h"
#include "pointcloud/scenes.h"
#include "pointcloud/surfel_rays.h"
#include "pointcloud/surfel_sampler.h"

namespace lvox {
namespace {

double spent(const std::vector<uint32_t>& counts, const std::vector<uint32_t>& size) {
  double sum = 0.0;
  for (size_t g = 0; g < counts.size(); ++g) sum += double(counts[g]) * size[g];
  return sum;
}

TEST(SurfelRays, NeymanCountsFollowTheDeviationsWithinTheirBoundsAndTheBudget) {
  // Four groups of 16, a mean of 4 rays: unbounded, the counts would be 256 / 112 times
  // the deviations (2.3, 4.6, 9.1, 0); the silent group gets the least, 1, and the others
  // share what is left in proportion, (256 - 16) / 112 times their deviations.
  const std::vector<double> deviation{1.0, 2.0, 4.0, 0.0};
  const std::vector<uint32_t> size(4, 16);
  const std::vector<uint32_t> counts = neymanCounts(deviation, size, 256.0, 1, 64);
  EXPECT_EQ(counts[3], 1u);
  EXPECT_NEAR(counts[0], 240.0 / 112.0, 0.5);
  EXPECT_NEAR(counts[1], 2 * 240.0 / 112.0, 0.5);
  EXPECT_NEAR(counts[2], 4 * 240.0 / 112.0, 0.5);
  EXPECT_NEAR(spent(counts, size), 256.0, 8.0);  // within half a group of the budget
  // A bound that binds: the largest is held at 6, and the rest take what it leaves.
  const std::vector<uint32_t> capped = neymanCounts(deviation, size, 256.0, 1, 6);
  EXPECT_EQ(capped[2], 6u);
  EXPECT_EQ(capped[3], 1u);
  EXPECT_GT(capped[1], counts[1]);
  EXPECT_NEAR(spent(capped, size), 256.0, 8.0);
  // Nothing tells the groups apart: every group the mean.
  const std::vector<uint32_t> even = neymanCounts(std::vector<double>(4, 0.0), size, 256.0, 1, 64);
  for (uint32_t c : even) EXPECT_EQ(c, 4u);
  // A budget the bounds cannot spend: every group at its bound.
  for (uint32_t c : neymanCounts(deviation, size, 1e6, 1, 8)) EXPECT_LE(c, 8u);
  // Groups of unequal sizes: the running rounding keeps the sum within half a group.
  const std::vector<double> many{0.3, 1.7, 0.9, 2.2, 0.05, 1.1, 0.6};
  const std::vector<uint32_t> sizes{16, 16, 7, 16, 16, 3, 16};
  const std::vector<uint32_t> uneven = neymanCounts(many, sizes, 4.0 * 90, 1, 64);
  EXPECT_NEAR(spent(uneven, sizes), 360.0, 8.0);
}

TEST(SurfelRays, HalfTheRaysGoEvenlyAndHalfByTheDeviationOfTheRunsAround) {
  // 1024 surfels: 64 runs of 16 a side. Every side's one-ray estimate is 1, except that the
  // fronts of run 30 alternate between 0 and 2 (deviation 1.03). Pooled over 17 runs, the
  // fronts of runs 22-38 have deviation 1.03 / sqrt 17 and the rest none. Half the mean of
  // 4 rays goes evenly (2 a side); the other half, 2 x 2048 rays, to the 17 x 16 sides of
  // the pooled runs: 2 + 4096 / 272 = 17 each.
  std::vector<float> values(2048, 1.0f);
  for (size_t i = 30 * 16; i < 31 * 16; ++i) values[i] = (i % 2) ? 2.0f : 0.0f;
  const SurfelRays plan = plannedSurfelRays(values, 4, 7);
  ASSERT_EQ(plan.runs(), 64u);
  for (size_t s = 0; s < 1024; ++s) {
    EXPECT_EQ(plan.raysOf(s, false), 2) << s;
    const size_t run = s / 16;
    if (run >= 22 && run <= 38)
      EXPECT_NEAR(plan.raysOf(s, true), 17, 1) << s;  // 17.06, rounded as the sum goes
    else
      EXPECT_EQ(plan.raysOf(s, true), 2) << s;
  }
  EXPECT_NEAR(static_cast<double>(plan.totalRays()), 4.0 * 2048, 16.0);
  // Every estimate equal: every side the mean.
  const SurfelRays flat = plannedSurfelRays(std::vector<float>(128, 3.0f), 4, 7);
  EXPECT_EQ(flat.totalRays(), 4u * 128);
  // A partial last run counts its own sides only.
  const SurfelRays partial = uniformSurfelRays(37, 3, 1);
  EXPECT_EQ(partial.runs(), 3u);
  EXPECT_EQ(partial.totalRays(), 2u * 37 * 3);
}

TEST(SurfelRays, ARunsSidesStratifyTheHemisphereTogether) {
  // Each of a run's 16 sides alone puts its 4 rays one in each 2 x 2 stratum of the cosine
  // map; together their 64 rays fall one in each of the 8 x 8 strata (and of the 64 x 1
  // and 1 x 64 ones: the points are a (0,6,2)-net).
  const PointCloud pc(SurfelSet{}, LvoxelSet{});
  TraversalScratch scratch;
  const SurfelRays plan = uniformSurfelRays(32, 4, 11);
  for (bool front : {true, false}) {
    std::vector<int> fine(64, 0), rows(64, 0), cols(64, 0);
    for (size_t s = 16; s < 32; ++s) {  // the second run
      GatherOptions o;
      o.samples = plan.raysOf(s, front);
      o.strata = plan.strataOf(s, front);
      test::RayDirections sink;
      Rng rng(3, s);
      gatherIrradianceInto(pc, Vec3(0.0f), Vec3(0, 0, 1), o, rng, scratch, sink);
      ASSERT_EQ(sink.dirs.size(), 4u);
      std::vector<int> coarse(4, 0);
      for (const Vec3& d : sink.dirs) {
        const auto [u1, u2] = test::cosineMapPoint(d);
        const int a = std::min(7, static_cast<int>(u1 * 8.0f));
        const int b = std::min(7, static_cast<int>(u2 * 8.0f));
        ++coarse[static_cast<size_t>((a / 4) * 2 + b / 4)];
        ++fine[static_cast<size_t>(a * 8 + b)];
        ++rows[static_cast<size_t>(std::min(63, static_cast<int>(u1 * 64.0f)))];
        ++cols[static_cast<size_t>(std::min(63, static_cast<int>(u2 * 64.0f)))];
      }
      for (int c : coarse) EXPECT_EQ(c, 1) << s;
    }
    for (size_t k = 0; k < 64; ++k) {
      EXPECT_EQ(fine[k], 1) << k;
      EXPECT_EQ(rows[k], 1) << k;
      EXPECT_EQ(cols[k], 1) << k;
    }
  }
  // The two sides and the neighbouring runs are scrambled apart.
  EXPECT_NE(plan.strataOf(3, true).seedU, plan.strataOf(3, false).seedU);
  EXPECT_NE(plan.strataOf(3, true).seedU, plan.strataOf(19, true).seedU);
  EXPECT_EQ(plan.strataOf(3, true).seedU, plan.strataOf(12, true).seedU);
}

// A closed unit box of albedo 0.5 whose inner sides reflect direct radiance 1, except a
// 0.2 x 0.2 patch of the ceiling at 50 (a wall beside a lamp): sides near the patch see it
// large and are noisy, the rest little.
PointCloud boxWithBrightPatch() {
  TriangleMesh mesh;
  test::addBox(mesh, Vec3(0, 0, 0), Vec3(1, 1, 1), 0);
  const Material m{"box", RGB(0.5f), RGB(0.0f)};
  PointCloud pc(sampleSurfelsUniform(mesh, {m}, {0.05f, 1.15f, 4}), LvoxelSet{});
  cacheDirectLight(
      pc,
      [](const SurfelLightQuery& q) {
        const Vec3 inward = q.position.y > 0.999f ? Vec3(0, -1, 0) : Vec3(0.0f);
        if (dot(q.normal, inward) > 0.5f && std::abs(q.position.x - 0.5f) < 0.1f &&
            std::abs(q.position.z - 0.5f) < 0.1f)
          return RGB(50.0f);
        // The inner side: towards the box's centre.
        return dot(q.normal, Vec3(0.5f, 0.5f, 0.5f) - q.position) > 0.0f ? RGB(1.0f) : RGB(0.0f);
      },
      [](const LvoxelLightQuery&) { return RGB(0.0f); });
  return pc;
}

std::vector<float> innerRadiance(const PointCloud& pc) {
  std::vector<float> out(pc.surfels().size());
  for (size_t i = 0; i < out.size(); ++i) out[i] = pc.surfels().radianceFront[i].x;
  return out;
}

TEST(SurfelRays, RaysByDeviationLeaveTheCloudLessNoisyAndAsBright) {
  // The same number of rays (a mean of 4 per side) spread evenly or planned by a
  // preview, over 24 seeds each, against the cloud a mean of 256 rays per side gives
  // (4 seeds of 64; its own noise adds 1/64 of a 4-ray cloud's variance to both).
  GatherOptions o;
  o.samples = 4;
  const InterreflectionPasses passes(24);
  std::vector<double> reference;
  {
    std::vector<double> sum;
    for (uint64_t seed = 101; seed < 105; ++seed) {
      PointCloud pc = boxWithBrightPatch();
      const SurfelRays many = uniformSurfelRays(pc.surfels().size(), 64, seed);
      cacheInterreflection(pc, IsotropicPhase{}, o, o, passes, seed, singleProcess(), {}, &many);
      const std::vector<float> l = innerRadiance(pc);
      sum.resize(l.size(), 0.0);
      for (size_t i = 0; i < l.size(); ++i) sum[i] += l[i] / 4.0;
    }
    reference = sum;
  }
  const double referenceMean =
      std::accumulate(reference.begin(), reference.end(), 0.0) / double(reference.size());
  double squared[2] = {0.0, 0.0}, mean[2] = {0.0, 0.0};
  uint64_t rays[2] = {0, 0};
  const int seeds = 24;
  for (int planned = 0; planned < 2; ++planned)
    for (uint64_t seed = 1; seed <= static_cast<uint64_t>(seeds); ++seed) {
      PointCloud pc = boxWithBrightPatch();
      uint64_t previewRays = 0;
      const SurfelRays plan = planned ? previewSurfelRays(pc, IsotropicPhase{}, o, o, passes, 4,
                                                          seed, singleProcess(), previewRays)
                                      : uniformSurfelRays(pc.surfels().size(), 4, seed);
      const InterreflectionStats stats = cacheInterreflection(pc, IsotropicPhase{}, o, o, passes,
                                                              seed, singleProcess(), {}, &plan);
      rays[planned] += stats.gatherRays;
      const std::vector<float> l = innerRadiance(pc);
      for (size_t i = 0; i < l.size(); ++i) {
        squared[planned] +=
            (l[i] - reference[i]) * (l[i] - reference[i]) / double(l.size() * seeds);
        mean[planned] += l[i] / double(l.size() * seeds);
      }
    }
  std::printf(
      "bright patch box: mean squared error even %.4g, planned %.4g (ratio %.3f); means %.4f, "
      "%.4f against %.4f; rays %llu, %llu\n",
      squared[0], squared[1], squared[1] / squared[0], mean[0], mean[1], referenceMean,
      static_cast<unsigned long long>(rays[0]), static_cast<unsigned long long>(rays[1]));
  EXPECT_LT(squared[1], 0.8 * squared[0]);  // measured 0.69
  EXPECT_NEAR(double(rays[1]) / double(rays[0]), 1.0, 0.01);
  // As bright: the even clouds' mean is 0.44 % above the reference's, the upward bias of
  // rays that every pass reuses (docs/pcb.md, "The near field"), which falls with the
  // rays; the planned clouds', whose rays are where the light varies, 0.21 % below it.
  EXPECT_NEAR(mean[0] / referenceMean, 1.0, 0.006);
  EXPECT_NEAR(mean[1] / referenceMean, 1.0, 0.006);
}

}  // namespace
}  // namespace lvox
