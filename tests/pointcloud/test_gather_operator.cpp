#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "pointcloud/gather_operator.h"
#include "pointcloud/light_cache.h"
#include "pointcloud/lvoxel_sampler.h"
#include "pointcloud/scenes.h"
#include "pointcloud/surfel_lookup.h"
#include "pointcloud/surfel_sampler.h"
#include "src/geometry/ray_tracer.h"

namespace lvox {
namespace {

// Closed unit box of albedo `albedo` (coarse lattice: its borders are covered), direct
// radiance 1 on both sides of every surfel, lvoxels of the given medium inside.
PointCloud litBox(float albedo, float spacing, const LvoxelSet& lvoxels = {}) {
  TriangleMesh mesh;
  test::addBox(mesh, Vec3(0, 0, 0), Vec3(1, 1, 1), 0);
  const Material m{"box", RGB(albedo), RGB(0.0f)};
  PointCloud pc(sampleSurfelsUniform(mesh, {m}, {spacing, 1.15f, 4}), lvoxels);
  cacheDirectLight(
      pc, [](const SurfelLightQuery&) { return RGB(1.0f); },
      [](const LvoxelLightQuery&) { return RGB(0.5f); });
  return pc;
}

// Recording a gather and applying the weights to the cloud's radiance must give what
// the gather itself returns with the same random numbers: surfels, lvoxels, lvoxel
// clusters and the background all go through the weights: to float rounding where the
// weights are colour, to half rounding (2^-11 of each weight, all positive here) where
// they are grey. Returns the operator's bytes per entry.
double checkOneApplication(const RGB& sigmaT) {
  const bool grey = sigmaT.x == sigmaT.y && sigmaT.x == sigmaT.z;
  const float tolerance = grey ? 1.0f / 2048.0f : 1e-5f;
  const test::BoxMedium medium(Vec3(0.2f, 0.2f, 0.2f), Vec3(0.8f, 0.6f, 0.8f), RGB(0.7f), sigmaT);
  const PointCloud pc = litBox(0.5f, 0.05f, sampleLvoxels(medium, {0.1f}));
  GatherOptions o;
  o.samples = 64;
  o.maxLvoxelSolidAngle = 0.03f;
  o.background = RGB(0.25f, 0.5f, 1.0f);
  const Vec3 points[] = {{0.5f, 0.05f, 0.5f}, {0.3f, 0.4f, 0.7f}};
  const Vec3 normals[] = {{0, 1, 0}, normalize(Vec3(1, 1, -1))};
  const GatherOperator op(pc, 2, [&](size_t row, GatherRecorder& rec, TraversalScratch& scratch) {
    Rng rng(7, row);
    gatherIrradianceInto(pc, points[row], normals[row], o, rng, scratch, rec);
  });
  std::vector<RGB> applied;
  op.apply(op.columns().values(pc, o.background), applied);
  EXPECT_EQ(applied.size(), 2u);
  for (size_t row = 0; row < 2; ++row) {
    Rng rng(7, row);
    const RGB direct = gatherIrradiance(pc, points[row], normals[row], o, rng);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(applied[row][c], direct[c], tolerance * direct[c]);
    EXPECT_GT(direct.x, 0.5f);  // the walls are seen (radiance 1) through the medium
  }
  EXPECT_GT(op.entries(), 2u);
  const size_t rowBytes = 2 * sizeof(uint32_t);
  return double(op.memoryBytes() - rowBytes) / double(op.entries());
}

TEST(GatherOperator, OneApplicationEqualsTheGathersItRecorded) {
  // A grey medium gives grey weights, stored as one half float per entry ...
  EXPECT_DOUBLE_EQ(checkOneApplication(RGB(2.0f)), sizeof(uint32_t) + 2);
  // ... a coloured one keeps its RGB weights.
  EXPECT_DOUBLE_EQ(checkOneApplication(RGB(2.0f, 1.0f, 0.5f)), sizeof(uint32_t) + sizeof(RGB));
}

TEST(GatherOperator, InterreflectionReachesTheRadiosityOfAClosedBox) {
  // Inside a closed box whose walls all emit (here: reflect direct light of) radiance 1
  // with albedo rho, every bounce multiplies by rho: L = 1 / (1 - rho) = 2 for rho = 0.5.
  // 4 rays per side: a gather ray always hits a wall (closed lattice), so there is no
  // noise to allow for; 24 passes leave 0.5^24 of the series. The outer sides see
  // nothing, except near the box corners: a disk is cut along one border edge only
  // (DiskClip), so at a corner it can still stick out past the other edge and show its
  // lit inner side. Uncut, 132 of the 215 outer sides saw such disks; cut, 21.
  PointCloud pc = litBox(0.5f, 0.2f);
  GatherOptions o;
  o.samples = 4;
  const InterreflectionStats stats = cacheInterreflection(pc, IsotropicPhase{}, o, o, 24, 5);
  const CloudSurfels& s = pc.surfels();
  float worst = 0.0f;
  size_t outerLit = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    worst = std::max(worst, std::abs(s.radianceFront[i].x - 2.0f));
    ASSERT_GE(s.radianceBack[i].x, 1.0f - 1e-6f);
    outerLit += s.radianceBack[i].x > 1.0f + 1e-6f;
  }
  std::printf(
      "closed box, rho 0.5: worst |L - 2| = %.2e over %zu surfels, last pass %.2e; "
      "%zu outer sides see edge disks\n",
      worst, s.size(), stats.lastPassChange, outerLit);
  EXPECT_LT(worst, 1e-4f);
  EXPECT_LT(outerLit * 5, s.size());
  EXPECT_EQ(stats.gatherRays, 2 * s.size() * 4);
  EXPECT_LT(stats.lastPassChange, 1e-6);
}

TEST(GatherOperator, PassesAddBouncesOneAtATime) {
  // Pass n gives the partial sum 1 + rho + ... + rho^n of the series.
  for (int passes : {1, 2, 3}) {
    PointCloud pc = litBox(0.5f, 0.25f);
    GatherOptions o;
    o.samples = 4;
    cacheInterreflection(pc, IsotropicPhase{}, o, o, passes, 5);
    const float expected = 2.0f - std::pow(0.5f, static_cast<float>(passes));
    for (size_t i = 0; i < pc.surfels().size(); ++i)
      ASSERT_NEAR(pc.surfels().radianceFront[i].x, expected, 1e-5f) << passes;
  }
}

// A closed box of albedo 0.9 converges slowly (L = 1 / (1 - 0.9) = 10; pass n leaves
// 0.9^(n+1) of it out), and every pass changes the inner sides by exactly 0.9 times the one
// before: the series is one geometric mode, the case the pass plan's estimates are exact
// for (light_cache.h, InterreflectionPasses).
// The closed box of albedo `albedo` (inner sides converge to L = 1 / (1 - albedo)) through
// `plan`; `worst`: the largest |L - 1 / (1 - albedo)| over the inner sides; `radiance`, if
// given, the inner sides' result.
InterreflectionStats runLitBox(float albedo, const InterreflectionPasses& plan, float* worst,
                               const std::function<bool(uint64_t)>& reserveMixing = {},
                               std::vector<RGB>* radiance = nullptr) {
  PointCloud pc = litBox(albedo, 0.25f);
  GatherOptions o;
  o.samples = 4;
  const InterreflectionStats stats = cacheInterreflection(
      pc, IsotropicPhase{}, o, o, plan, 5, singleProcess(), {}, nullptr, reserveMixing);
  *worst = 0.0f;
  for (size_t i = 0; i < pc.surfels().size(); ++i)
    *worst = std::max(*worst, std::abs(pc.surfels().radianceFront[i].x - 1.0f / (1.0f - albedo)));
  if (radiance) *radiance = pc.surfels().radianceFront;
  return stats;
}
InterreflectionStats runAlbedo09Box(const InterreflectionPasses& plan, float* worst) {
  return runLitBox(0.9f, plan, worst);
}

TEST(GatherOperator, PassesStopAtTheirToleranceAndTheTailCompletesTheSeries) {
  const auto run = runAlbedo09Box;
  float worst = 0.0f;
  // Without a tolerance, all the passes: 24 leave 0.9^25 = 7.2 % of the light out.
  EXPECT_EQ(run(24, &worst).passes, 24);
  EXPECT_NEAR(worst, 10.0f * std::pow(0.9f, 25.0f), 1e-3f);
  // With one, the passes stop once the rest they estimate is below 1e-3 of the cloud's
  // light (inner sides about 10, outer ones 1): at most 0.011 on an inner side. One pass
  // fewer would leave more than that.
  const InterreflectionStats stopped = run({500, 1e-3, false}, &worst);
  std::printf("albedo 0.9: %d passes, ratio %.6f, worst |L - 10| %.2e\n", stopped.passes,
              stopped.ratio, worst);
  EXPECT_NEAR(stopped.ratio, 0.9, 1e-3);  // changes of 1e-3 on values of 10 in floats
  EXPECT_LT(stopped.passes, 100);
  EXPECT_LT(worst, 0.011f);
  EXPECT_GT(10.0f * std::pow(0.9f, static_cast<float>(stopped.passes)), 0.011f);
  EXPECT_EQ(stopped.tail, 0.0);
  // The geometric tail adds the rest: exact for one mode, after as many passes.
  const InterreflectionStats tailed = run({500, 1e-3, true}, &worst);
  std::printf("with the tail: %d passes, rest added %.2e, worst |L - 10| %.2e\n", tailed.passes,
              tailed.tail, worst);
  EXPECT_EQ(tailed.passes, stopped.passes);
  EXPECT_GT(tailed.tail, 0.0);
  EXPECT_LT(tailed.tail, 1e-3);
  EXPECT_LT(worst, 2e-4f);
  // Black walls return nothing: the first pass changes nothing, and it is the last.
  PointCloud black = litBox(0.0f, 0.25f);
  GatherOptions o;
  o.samples = 4;
  EXPECT_EQ(cacheInterreflection(black, IsotropicPhase{}, o, o, {500, 1e-3, true}, 5).passes, 1);
  EXPECT_EQ(cacheInterreflection(black, IsotropicPhase{}, o, o, 6, 5).passes, 6);  // no tolerance
}

// Anderson mixing of the passes (InterreflectionPasses::andersonDepth): the closed box's
// one mode at 0.9 goes in a few mixed passes where plain ones take 64, within the
// same bound on the rest; without a tolerance the passes stay plain (exact bounces).
TEST(GatherOperator, MixedPassesReachTheToleranceInAFractionOfThePasses) {
  const auto run = runAlbedo09Box;
  float plainWorst = 0.0f, worst = 0.0f;
  const InterreflectionStats plain = run({500, 1e-3, false}, &plainWorst);
  const InterreflectionStats mixed = run({500, 1e-3, false, 3}, &worst);
  std::printf("albedo 0.9: plain %d passes (worst %.2e), mixed %d (%d mixed, worst %.2e)\n",
              plain.passes, plainWorst, mixed.passes, mixed.mixedPasses, worst);
  EXPECT_LT(mixed.passes, plain.passes / 4);
  EXPECT_GT(mixed.mixedPasses, 0);
  EXPECT_LT(worst, 0.011f);
  const InterreflectionStats exact = run({24, 0.0, false, 3}, &worst);
  EXPECT_EQ(exact.passes, 24);
  EXPECT_EQ(exact.mixedPasses, 0);
  EXPECT_NEAR(worst, 10.0f * std::pow(0.9f, 25.0f), 1e-3f);
}

// The plain stop rule's prediction of its own passes (plainPassesLeft) on one geometric
// mode of ratio r, pass k changing the light by r^k and the light the sum of those: after 6
// passes it predicts the passes the rule (the one in cacheInterreflection) then runs, within
// the one its rounding up adds.
TEST(GatherOperator, PlainPassesLeftPredictsTheStopOfOneGeometricMode) {
  for (double r : {0.6, 0.8, 0.9, 0.95}) {
    std::vector<double> changes;
    double total = 0.0, predicted = -1.0;
    int passes = 0;
    for (int pass = 0; pass < 2000; ++pass) {
      const double ratio = bounceRatio(changes);
      if (ratio > 0.0 && changes.back() * ratio * ratio / (1.0 - ratio) < 1e-3 * total) break;
      changes.push_back(std::pow(r, pass));
      total += changes.back();
      passes = pass + 1;
      if (passes == 6) predicted = plainPassesLeft(changes, total, 1e-3);
    }
    std::printf("ratio %.2f: %d plain passes, %.2f predicted left after 6\n", r, passes, predicted);
    EXPECT_GT(predicted, passes - 6 - 1.0) << r;
    EXPECT_LE(predicted, passes - 6) << r;
  }
  EXPECT_EQ(plainPassesLeft({1.0, 0.5}, 1.5, 1e-3), 0.0);        // no ratio from two passes
  EXPECT_EQ(plainPassesLeft({1.0, 0.5, 1e-4}, 1.5, 1e-3), 0.0);  // it would stop now
}

// "bounce_mixing_depth": "auto": the albedo-0.9 box, with many passes left after 6, goes on
// mixed and ends in a fraction of the plain passes within the same bound on the rest; the
// albedo-0.5 box, few left, stays plain, bit for bit; and where the mixer's memory is
// refused the passes stay plain too.
TEST(GatherOperator, AutoMixingMixesOnlyWhereManyPassesAreLeft) {
  const InterreflectionPasses autoPlan(500, 1e-3, false, kAutoBounceMixing);
  ASSERT_TRUE(autoPlan.mayMix());
  ASSERT_FALSE(autoPlan.mixes());
  float plainWorst = 0.0f, worst = 0.0f;
  const InterreflectionStats plain = runAlbedo09Box({500, 1e-3, false}, &plainWorst);
  const InterreflectionStats mixed = runAlbedo09Box(autoPlan, &worst);
  std::printf(
      "albedo 0.9, auto: %d passes (%d mixed, %.1f predicted plain ones left), worst "
      "%.2e; plain %d\n",
      mixed.passes, mixed.mixedPasses, mixed.predictedPasses, worst, plain.passes);
  EXPECT_GE(mixed.predictedPasses, InterreflectionPasses::kAutoMixingPasses);
  EXPECT_LT(mixed.passes, plain.passes / 3);
  EXPECT_GT(mixed.mixedPasses, 0);
  EXPECT_EQ(mixed.mixedPasses, mixed.passes - InterreflectionPasses::kAutoDecisionPass - 1);
  EXPECT_LT(worst, 0.011f);

  uint64_t asked = 0;
  const InterreflectionStats refused =
      runLitBox(0.9f, autoPlan, &worst, [&](uint64_t bytes) { return asked = bytes, false; });
  EXPECT_GT(asked, 0u);
  EXPECT_EQ(refused.passes, plain.passes);
  EXPECT_EQ(refused.mixedPasses, 0);

  std::vector<RGB> plainHalf, autoHalf;
  const InterreflectionStats fastPlain = runLitBox(0.5f, {500, 1e-3, true}, &worst, {}, &plainHalf);
  const InterreflectionStats fastAuto =
      runLitBox(0.5f, {500, 1e-3, true, kAutoBounceMixing}, &worst, {}, &autoHalf);
  EXPECT_GT(fastPlain.passes, InterreflectionPasses::kAutoDecisionPass);
  EXPECT_LT(fastAuto.predictedPasses, InterreflectionPasses::kAutoMixingPasses);
  EXPECT_GT(fastAuto.predictedPasses, 0.0);
  EXPECT_EQ(fastAuto.passes, fastPlain.passes);
  EXPECT_EQ(fastAuto.mixedPasses, 0);
  EXPECT_EQ(fastAuto.tail, fastPlain.tail);
  ASSERT_EQ(autoHalf.size(), plainHalf.size());
  for (size_t i = 0; i < autoHalf.size(); ++i) ASSERT_EQ(autoHalf[i].x, plainHalf[i].x) << i;
}

TEST(GatherOperator, EachKindOfRowSeesItsOwnBackground) {
  // pcb gives the sky to the surfels' gathers and not to the lvoxels' (their direct light
  // holds it). The closed box's inner sides never see it (L = 2 as above); its outer sides
  // see nothing else, away from the corners' edge disks: L = 1 + rho B. The lvoxels of a
  // cube far from the box see almost nothing but the sky, so with a black background of
  // their own they gather almost nothing, and with the sky most of it.
  const test::BoxMedium far(Vec3(20, 0, 0), Vec3(20.5f, 0.5f, 0.5f), RGB(0.1f), RGB(1.0f));
  const RGB sky(0.6f, 0.3f, 0.2f);
  auto run = [&](const RGB& lvoxelBackground) {
    PointCloud pc = litBox(0.5f, 0.2f, sampleLvoxels(far, {0.25f}));
    cacheDirectLight(  // dark lvoxels: what they gather comes from the box and the sky
        pc, [](const SurfelLightQuery&) { return RGB(1.0f); },
        [](const LvoxelLightQuery&) { return RGB(0.0f); });
    GatherOptions surfels, lvoxels;
    surfels.samples = lvoxels.samples = 4;
    surfels.background = sky;
    lvoxels.background = lvoxelBackground;
    cacheInterreflection(pc, IsotropicPhase{}, surfels, lvoxels, 24, 5);
    return pc;
  };
  const PointCloud dark = run(RGB(0.0f));
  const CloudSurfels& s = dark.surfels();
  size_t outerSky = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    ASSERT_NEAR(s.radianceFront[i].x, 2.0f, 1e-4f);
    ASSERT_NEAR(s.radianceFront[i].z, 2.0f, 1e-4f);
    const RGB expected = RGB(1.0f) + sky * 0.5f;
    outerSky += std::abs(s.radianceBack[i].x - expected.x) < 1e-5f &&
                std::abs(s.radianceBack[i].z - expected.z) < 1e-5f;
  }
  std::printf("outer sides lit by the sky alone: %zu of %zu\n", outerSky, s.size());
  EXPECT_GT(outerSky * 5, s.size() * 4);
  const PointCloud lit = run(sky);
  const LvoxelLight& a = dark.lvoxels().light;
  const LvoxelLight& b = lit.lvoxels().light;
  ASSERT_GT(a.occupiedCount(), 0u);
  double darkSum = 0.0, litSum = 0.0;
  for (uint32_t slot = 0; slot < a.occupiedCount(); ++slot) {
    darkSum += a.multiScatter(slot)[0].x;
    litSum += b.multiScatter(slot)[0].x;
  }
  std::printf("lvoxels' gathered light: black background %.4g, the sky %.4g\n", darkSum, litSum);
  EXPECT_GT(litSum, 0.0);
  EXPECT_LT(darkSum, 0.01 * litSum);
}

TEST(GatherOperator, DoesNotDependOnTheThreadCount) {
  const test::BoxMedium medium(Vec3(0.3f, 0.3f, 0.3f), Vec3(0.7f, 0.7f, 0.7f), RGB(0.2f),
                               RGB(3.0f));
  auto run = [&] {
    PointCloud pc = litBox(0.7f, 0.1f, sampleLvoxels(medium, {0.1f}));
    GatherOptions o;
    o.samples = 8;
    cacheInterreflection(pc, IsotropicPhase{}, o, o, 6, 9);
    return pc;
  };
  const PointCloud a = run();
  PointCloud b;
  {
    tbb::task_arena one(1);
    one.execute([&] { b = run(); });
  }
  for (size_t i = 0; i < a.surfels().size(); ++i)
    ASSERT_EQ(a.surfels().radianceFront[i], b.surfels().radianceFront[i]);
  for (uint32_t s = 0; s < a.lvoxels().light.occupiedCount(); ++s)
    ASSERT_EQ(a.lvoxels().light.multiScatter(s)[0], b.lvoxels().light.multiScatter(s)[0]);
}

// Directional lvoxels (anisotropic media: nine coefficients per colour, docs/pcb.md): an
// lvoxel sends sum c_k Yhat_k(wi) along a gather ray of direction wi. Rows of one known
// ray each: the operator's row is that ray's radiance (as a RadianceSink finds it, lvoxels
// and their clusters evaluated along the ray) times Yhat_k(wi), the ray's share of the
// row's spherical-harmonic projection.
// The lit box around a forward-scattering medium of directional lvoxels (nine coefficients).
PointCloud boxWithDirectionalLvoxels() {
  const test::BoxMedium medium(Vec3(0.2f, 0.2f, 0.2f), Vec3(0.8f, 0.6f, 0.8f), RGB(0.1f),
                               RGB(1.5f));
  LvoxelSet lvoxels = sampleLvoxels(medium, {0.1f});
  lvoxels.light.setCoefficients(kShCoefficients);
  lvoxels.phaseMoments.assign(lvoxels.size(), {0.6f, 0.3f});
  return litBox(0.5f, 0.05f, lvoxels);
}

// Three rays from the box's floor, the first two through the medium.
const Vec3 kRayOrigin(0.5f, 0.05f, 0.5f);
const Vec3 kRayDirections[] = {normalize(Vec3(0.2f, 1, 0.1f)), normalize(Vec3(-0.5f, 1, 0.3f)),
                               normalize(Vec3(0.6f, 0.5f, -0.4f))};

// An operator of three rows, row r the ray kRayDirections[r]; with `constants`, the rows'
// constants (hit light) go there.
GatherOperator recordRays(const PointCloud& pc, const GatherOptions& o,
                          RGB (*constants)[kShCoefficients] = nullptr) {
  return GatherOperator(pc, 3, [&](size_t row, GatherRecorder& rec, TraversalScratch& scratch) {
    if (constants) {
      std::fill(constants[row], constants[row] + kShCoefficients, RGB(0.0f));
      rec.constant = constants[row];
    }
    traceGatherRay(pc, Ray{kRayOrigin, kRayDirections[row], o.rayOffset, kInf}, o, 1.0f, scratch,
                   rec);
  });
}

// What a RadianceSink finds along ray `row`, and the ray's Yhat_k.
RGB sinkRadiance(const PointCloud& pc, const GatherOptions& o, size_t row,
                 float (&yhat)[kShCoefficients]) {
  TraversalScratch scratch;
  RadianceSink sink{pc, o.background};
  traceGatherRay(pc, Ray{kRayOrigin, kRayDirections[row], o.rayOffset, kInf}, o, 1.0f, scratch,
                 sink);
  shBasis(kRayDirections[row], kShCoefficients, yhat);
  return sink.radiance;
}

// The operator applied once to the cloud as it stands: kShCoefficients values per row.
std::vector<RGB> applyToCloud(const GatherOperator& op, const PointCloud& pc,
                              const RGB& background) {
  EXPECT_EQ(op.coefficients(), kShCoefficients);
  GatherValues values;
  op.valuesInto(pc, background, values);
  std::vector<RGB> applied;
  op.apply(values, applied);
  EXPECT_EQ(applied.size(), op.rows() * kShCoefficients);
  return applied;
}

TEST(GatherOperator, DirectionalLvoxelsAreEvaluatedAlongEachRayAndProjected) {
  PointCloud pc = boxWithDirectionalLvoxels();
  // Incident light from +x and from above: coefficients of bands 1 and 2.
  LvoxelLight& light = pc.mutableLvoxels().light;
  for (uint32_t c = 0; c < light.occupiedCount(); ++c) {
    RGB* d = light.directInScatter(c);
    d[0] = RGB(1.0f);
    d[3] = RGB(0.8f);  // x
    d[2] = RGB(0.4f);  // z
    d[6] = RGB(0.2f);  // 3 z^2 - 1
  }
  pc.updateAggregates();
  GatherOptions o;
  o.maxLvoxelSolidAngle = 0.03f;  // clusters too
  const std::vector<RGB> applied = applyToCloud(recordRays(pc, o), pc, o.background);
  for (size_t row = 0; row < 3; ++row) {
    float y[kShCoefficients];
    const RGB radiance = sinkRadiance(pc, o, row, y);
    for (int k = 0; k < kShCoefficients; ++k)
      EXPECT_NEAR(applied[row * kShCoefficients + static_cast<size_t>(k)].x, radiance.x * y[k],
                  (1.0f / 2048.0f) * (1.0f + std::abs(radiance.x * y[k])))
          << row << " " << k;
  }
  // The lvoxels' light depends on direction here: the rays see different lvoxel radiance
  // than their isotropic mean would give.
  float y[kShCoefficients];
  const RGB directional = sinkRadiance(pc, o, 0, y);
  pc.mutableLvoxels().phaseMoments.assign(pc.lvoxels().size(), {0.0f, 0.0f});
  pc.updateAggregates();
  const RGB isotropic = sinkRadiance(pc, o, 0, y);
  EXPECT_GT(std::abs(directional.x - isotropic.x), 0.01f * isotropic.x);
}

}  // namespace
}  // namespace lvox

namespace lvox {
namespace {

TEST(GatherOperator, ReservesEveryBlockItStoresAndStopsWhenRefused) {
  // The reservation callback sees the bytes of each block as it is stored (a render's
  // memory budget); they add up to the operator's memory, and a callback that throws stops
  // the build with its exception.
  const PointCloud pc = litBox(0.5f, 0.05f);
  GatherOptions o;
  o.samples = 4;
  const size_t rows = 3000;  // six blocks
  auto record = [&](size_t row, GatherRecorder& rec, TraversalScratch& scratch) {
    Rng rng(3, row);
    const CloudSurfels& s = pc.surfels();
    const size_t i = row % s.size();
    gatherIrradianceInto(pc, s.position(i), s.normal(i), o, rng, scratch, rec);
  };
  std::atomic<uint64_t> reserved{0};
  std::atomic<int> calls{0};
  const GatherOperator op(pc, rows, record, 0, 1, [&](uint64_t bytes) {
    reserved += bytes;
    ++calls;
  });
  EXPECT_EQ(calls.load(), 6);
  EXPECT_EQ(reserved.load(), op.memoryBytes());
  EXPECT_THROW(GatherOperator(pc, rows, record, 0, 1,
                              [](uint64_t) { throw std::runtime_error("over budget"); }),
               std::runtime_error);
}

// The renderer's delta lights at a traced hit (SurfaceHitLight), here a constant radiance.
struct ConstantHitLight final : SurfaceHitLight {
  RGB radiance;
  explicit ConstantHitLight(const RGB& l) : radiance(l) {}
  RGB reflected(const SurfaceHit&) const override { return radiance; }
  RGB reflected(const Vec3&, const Vec3&, const RGB& albedo) const override {
    return albedo * radiance;
  }
};

TEST(GatherOperator, TracedHitsLightJoinsEveryPassAsAConstant) {
  // The closed box with traced visibility, its surfels without light of their own, and
  // every gather hit reflecting radiance 1 (the delta lights' light, which the surfels
  // leave to the hits): pass 1 gives the inner sides rho * 1, and each further pass one
  // more bounce of it, L_P = rho + ... + rho^P. The outer sides' rays leave the box and
  // hit nothing: 0.
  TriangleMesh mesh;
  test::addBox(mesh, Vec3(0, 0, 0), Vec3(1, 1, 1), 0);
  const Material m{"box", RGB(0.5f), RGB(0.0f)};
  const RayTracer tracer(mesh);
  const ConstantHitLight light(RGB(1.0f));
  for (int passes : {1, 2, 3}) {
    PointCloud pc(sampleSurfelsUniform(mesh, {m}, {0.25f, 1.15f, 4}), LvoxelSet{});
    cacheDirectLight(
        pc, [](const SurfelLightQuery&) { return RGB(0.0f); },
        [](const LvoxelLightQuery&) { return RGB(0.0f); });
    const SurfelLookup lookup(pc.surfels(), 0.25f);
    GatherOptions o;
    o.samples = 4;
    o.tracer = &tracer;
    o.lookup = &lookup;
    o.hitLight = &light;
    cacheInterreflection(pc, IsotropicPhase{}, o, o, passes, 5);
    const float expected = 1.0f - std::pow(0.5f, static_cast<float>(passes));
    const CloudSurfels& s = pc.surfels();
    for (size_t i = 0; i < s.size(); ++i) {
      ASSERT_NEAR(s.radianceFront[i].x, expected, 1e-5f) << passes << " " << i;
      ASSERT_EQ(s.radianceBack[i].x, 0.0f) << passes << " " << i;
    }
  }
}

TEST(GatherOperator, TracedHitsLightIsProjectedLikeTheRayItArrivesBy) {
  // With directional lvoxels a row's result is the spherical-harmonic projection of its
  // rays' radiance; the hit light's share of a ray (behind the medium, so attenuated) is
  // projected with it: the row plus its constant equals the ray's whole radiance, as a
  // RadianceSink finds it, times Yhat_k.
  TriangleMesh mesh;
  test::addBox(mesh, Vec3(0, 0, 0), Vec3(1, 1, 1), 0);
  const RayTracer tracer(mesh);
  const PointCloud pc = boxWithDirectionalLvoxels();
  const SurfelLookup lookup(pc.surfels(), 0.05f);
  const ConstantHitLight light(RGB(0.75f, 0.5f, 0.25f));
  GatherOptions o;
  o.tracer = &tracer;
  o.lookup = &lookup;
  o.hitLight = &light;
  RGB constants[3][kShCoefficients];
  const std::vector<RGB> applied = applyToCloud(recordRays(pc, o, constants), pc, o.background);
  for (size_t row = 0; row < 3; ++row) {
    float y[kShCoefficients];
    const RGB radiance = sinkRadiance(pc, o, row, y);
    // The first two rays cross the medium: their hit light arrives attenuated.
    if (row < 2) {
      EXPECT_LT(constants[row][0].z, 0.25f * y[0] * 0.99f) << row;
    }
    EXPECT_GT(constants[row][0].z, 0.0f) << row;
    for (int k = 0; k < kShCoefficients; ++k)
      for (int c = 0; c < 3; ++c) {
        const float want = radiance[c] * y[k];
        EXPECT_NEAR(
            applied[row * kShCoefficients + static_cast<size_t>(k)][c] + constants[row][k][c], want,
            (1.0f / 2048.0f) * (1.0f + std::abs(want)))
            << row << " " << k << " " << c;
      }
  }
}

}  // namespace
}  // namespace lvox
