// The nearest-surfel lookup of ray-traced gathers (pointcloud/surfel_lookup.h): its cells
// are passed over by a distance bound, which must never change the answer.
#include <gtest/gtest.h>

#include <cmath>

#include "pointcloud/point_cloud.h"
#include "pointcloud/surfel_lookup.h"
#include "src/core/rng.h"

namespace lvox {
namespace {

// The lookup's definition, surfel by surfel: over the surfels of the 27 cells around p's
// cell, the smallest (metric, index) whose normal is within 60 degrees of n if that is
// within 4 cells, else the smallest at all within 2 cells, else -1.
long bruteForceNearest(const CloudSurfels& s, float cell, const Vec3& p, const Vec3& n) {
  auto cellOf = [cell](float v) { return static_cast<long>(std::floor(v / cell)); };
  float bestAligned = kInf, bestAny = kInf;
  long aligned = -1, any = -1;
  for (size_t i = 0; i < s.size(); ++i) {
    const Vec3& q = s.position(i);
    if (std::abs(cellOf(q.x) - cellOf(p.x)) > 1 || std::abs(cellOf(q.y) - cellOf(p.y)) > 1 ||
        std::abs(cellOf(q.z) - cellOf(p.z)) > 1)
      continue;
    const Vec3 d = q - p;
    const float off = dot(d, s.normal(i));
    const float behind = std::max(0.0f, -dot(d, n));
    const float d2 = dot(d, d) + 3.0f * off * off + 63.0f * behind * behind;
    const long li = static_cast<long>(i);
    if (d2 < bestAny) {  // ascending indices: the first of equals is the smallest
      bestAny = d2;
      any = li;
    }
    if (d2 < bestAligned && std::abs(dot(s.normal(i), n)) >= NearestSurfelChoice::kAligned) {
      bestAligned = d2;
      aligned = li;
    }
  }
  if (aligned >= 0 && bestAligned <= 16.0f * cell * cell) return aligned;
  return bestAny <= 4.0f * cell * cell ? any : -1;
}

Vec3 randomDirection(Rng& rng) {
  const float z = 2.0f * rng.uniform() - 1.0f, phi = 2.0f * kPi * rng.uniform();
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  return Vec3(r * std::cos(phi), r * std::sin(phi), z);
}

// Surfels scattered in a box at `corner`, some on a lattice of the cell size (exact ties of
// the metric), queried at random points with random normals and at lattice points: every
// answer must be the definition's.
void expectTheDefinitionsAnswers(const Vec3& corner) {
  Rng rng(3, 7);
  const float cell = 0.25f;
  SurfelSet set;
  set.resize(3000);
  for (size_t i = 0; i < set.size(); ++i) {
    const bool lattice = i % 3 == 0;
    const Vec3 p = lattice ? Vec3(cell * std::floor(8.0f * rng.uniform()),
                                  cell * std::floor(8.0f * rng.uniform()),
                                  cell * std::floor(8.0f * rng.uniform()))
                           : Vec3(2.0f * rng.uniform(), 2.0f * rng.uniform(), 2.0f * rng.uniform());
    set.position[i] = corner + p;
    set.normal[i] = lattice ? Vec3(0, 1, 0) : randomDirection(rng);
    set.radius[i] = 0.5f * cell;
    set.albedo[i] = RGB(0.5f);
  }
  const PointCloud pc(std::move(set), LvoxelSet{});
  const CloudSurfels& s = pc.surfels();
  const SurfelLookup lookup(s, cell);
  int found = 0;
  for (int k = 0; k < 20000; ++k) {
    const bool lattice = k % 4 == 0;
    const Vec3 p = lattice ? Vec3(cell * (0.5f + std::floor(8.0f * rng.uniform())),
                                  cell * std::floor(8.0f * rng.uniform()),
                                  cell * (0.5f + std::floor(8.0f * rng.uniform())))
                           : Vec3(-0.3f + 2.6f * rng.uniform(), -0.3f + 2.6f * rng.uniform(),
                                  -0.3f + 2.6f * rng.uniform());
    const Vec3 n = lattice ? Vec3(0, 1, 0) : randomDirection(rng);
    const long expected = bruteForceNearest(s, cell, corner + p, n);
    ASSERT_EQ(lookup.nearest(corner + p, n), expected) << k << " at " << corner + p;
    found += expected >= 0;
  }
  EXPECT_GT(found, 15000);  // most queries have an answer: the test is not vacuous
}

TEST(SurfelLookup, PassingCellsOverNeverChangesTheAnswer) {
  // The box spans cells -1 to 9 of every axis: blocks of 4 x 4 x 4 cells on both sides
  // of zero, where a cell's block and place in it come from floor division.
  expectTheDefinitionsAnswers(Vec3(0.0f));
}

TEST(SurfelLookup, AnswersAreTheSameAwayFromTheOrigin) {
  // Negative cells in every block position, and cells far from zero (-4,000 and 2,400).
  expectTheDefinitionsAnswers(Vec3(-0.6f, -37.3f, -1000.1f));
  expectTheDefinitionsAnswers(Vec3(600.05f, 0.3f, -2.2f));
}

TEST(SurfelLookup, AWallCostsFewBytesPerSurfel) {
  // A wall of 200 x 200 surfels at the cell size, as the sampler leaves them: one surfel
  // per cell. Cells are held in blocks of 4 x 4 x 4, so the wall fills 16 of a block's 64,
  // and a block's 24 bytes (in a table at most half full) come to 3 to 6 per cell; with
  // the cell's start and the surfel's index, 11 to 14 per surfel (12.9 here). A table of
  // single cells took 29 here (8-byte keys, 4-byte starts, a 4-byte slot table of 131,072).
  const float cell = 0.1f;
  SurfelSet set;
  set.resize(200 * 200);
  for (size_t i = 0; i < set.size(); ++i) {
    set.position[i] = Vec3(cell * (0.5f + static_cast<float>(i % 200)),
                           cell * (0.5f + static_cast<float>(i / 200)), 0.35f);
    set.normal[i] = Vec3(0, 0, 1);
    set.radius[i] = 0.5f * cell;
    set.albedo[i] = RGB(0.5f);
  }
  const PointCloud pc(std::move(set), LvoxelSet{});
  const SurfelLookup lookup(pc.surfels(), cell);
  const double perSurfel =
      static_cast<double>(lookup.memoryBytes()) / static_cast<double>(pc.surfels().size());
  EXPECT_LT(perSurfel, 14.5);
  EXPECT_GT(perSurfel, 8.0);  // the cells' starts and the surfels' indices at least
  // And it finds them: the surfel nearest a point of the wall is the one of its cell.
  const long found = lookup.nearest(Vec3(0.52f, 0.31f, 0.36f), Vec3(0, 0, 1));
  ASSERT_GE(found, 0);
  const Vec3& q = pc.surfels().position(static_cast<size_t>(found));
  EXPECT_NEAR(q.x, 0.55f, 1e-5f);
  EXPECT_NEAR(q.y, 0.35f, 1e-5f);
}

TEST(SurfelLookup, NoSurfelsFindsNone) {
  // A cloud of lvoxels only (a medium in an empty scene): the table holds no block.
  const PointCloud pc(SurfelSet{}, LvoxelSet{});
  const SurfelLookup lookup(pc.surfels(), 0.25f);
  EXPECT_TRUE(lookup.empty());
  EXPECT_EQ(lookup.nearest(Vec3(0.1f, -3.0f, 2.0f), Vec3(0, 1, 0)), -1);
  EXPECT_EQ(lookup.nearest(Vec3(0.0f), Vec3(0, 0, 1)), -1);
}

}  // namespace
}  // namespace lvox
