// The lvoxel lattice (lvoxel_lattice.h): which cubes make one, the cells it lists, the
// order its march visits them in, and what a sparse lattice costs. That lvoxel-only rays
// visit what the heap traversal visits is test_traversal_exact.cpp's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "pointcloud/lvoxel_lattice.h"
#include "pointcloud/lvoxel_sampler.h"
#include "pointcloud/scenes.h"
#include "src/core/rng.h"
#include "src/core/sampling.h"

namespace lvox {
namespace {

std::vector<CubeElement> cubesOn(float spacing, const std::vector<std::array<int, 3>>& cells,
                                 const Vec3& origin = Vec3(0.3f, -1.7f, 2.1f)) {
  std::vector<CubeElement> cubes;
  for (const auto& c : cells)
    cubes.push_back({origin + (Vec3(static_cast<float>(c[0]), static_cast<float>(c[1]),
                                    static_cast<float>(c[2])) +
                               Vec3(0.5f)) *
                                  spacing,
                     0.5f * spacing});
  return cubes;
}

std::vector<uint32_t> listOf(const uint32_t* p) {
  std::vector<uint32_t> out;
  for (; p; ++p) {
    out.push_back(*p & LvoxelLattice::kIndexMask);
    if (*p & LvoxelLattice::kLastInCell) break;
  }
  return out;
}

TEST(LvoxelLattice, CubesOfOneSizeOnOneGridMakeOne) {
  const std::vector<CubeElement> cubes =
      cubesOn(0.25f, {{0, 0, 0}, {3, 1, 2}, {3, 1, 2}, {9, 0, 17}, {0, 0, 0}, {3, 1, 2}});
  const auto lattice = LvoxelLattice::of(cubes);
  ASSERT_TRUE(lattice);
  EXPECT_EQ(lattice->cells(), (std::array<int32_t, 3>{10, 2, 18}));
  EXPECT_FLOAT_EQ(lattice->spacing(), 0.25f);
  // A cell's cubes in index order, the last one flagged; empty cells have none.
  EXPECT_EQ(listOf(lattice->cubesIn(0, 0, 0)), (std::vector<uint32_t>{0, 4}));
  EXPECT_EQ(listOf(lattice->cubesIn(3, 1, 2)), (std::vector<uint32_t>{1, 2, 5}));
  EXPECT_EQ(listOf(lattice->cubesIn(9, 0, 17)), (std::vector<uint32_t>{3}));
  EXPECT_EQ(lattice->cubesIn(1, 0, 0), nullptr);
  EXPECT_EQ(lattice->cubesIn(9, 1, 17), nullptr);

  std::vector<CubeElement> resized = cubes;
  resized[3].halfSize *= 1.01f;
  EXPECT_FALSE(LvoxelLattice::of(resized)) << "cubes of two sizes";
  std::vector<CubeElement> shifted = cubes;
  shifted[3].centre.x += 0.3f * 0.25f;
  EXPECT_FALSE(LvoxelLattice::of(shifted)) << "a cube between cells";
  EXPECT_FALSE(LvoxelLattice::of({})) << "no cubes";
}

TEST(LvoxelLattice, SampledLvoxelsLieOnOne) {
  const test::BoxMedium fog(Vec3(0.1f, 0.2f, 0.3f), Vec3(1.3f, 0.9f, 0.8f), RGB(0.5f), RGB(1.0f));
  const LvoxelSet l = sampleLvoxels(fog, {0.07f});
  std::vector<CubeElement> cubes;
  for (size_t i = 0; i < l.size(); ++i) cubes.push_back({l.position[i], l.halfSize[i]});
  const auto lattice = LvoxelLattice::of(cubes);
  ASSERT_TRUE(lattice);
  size_t listed = 0;
  for (int32_t k = 0; k < lattice->cells()[2]; ++k)
    for (int32_t j = 0; j < lattice->cells()[1]; ++j)
      for (int32_t i = 0; i < lattice->cells()[0]; ++i)
        for (const uint32_t c : listOf(lattice->cubesIn(i, j, k))) {
          // Each cube is listed in the cell it fills.
          const Vec3 lo = lattice->bounds().lo + Vec3(float(i), float(j), float(k)) * 0.07f;
          EXPECT_NEAR(cubes[c].centre.x, lo.x + 0.035f, 1e-5f);
          EXPECT_NEAR(cubes[c].centre.y, lo.y + 0.035f, 1e-5f);
          EXPECT_NEAR(cubes[c].centre.z, lo.z + 0.035f, 1e-5f);
          ++listed;
        }
  EXPECT_EQ(listed, cubes.size());
}

// Every cube a ray crosses over more than a rounding, in the order it enters them: what a
// brute-force test of every cube gives.
TEST(LvoxelLattice, MarchVisitsTheCubesARayCrossesInOrder) {
  Rng rng(11, 0);
  std::vector<std::array<int, 3>> cells;
  for (int n = 0; n < 3000; ++n)
    cells.push_back({static_cast<int>(rng.uniform() * 20), static_cast<int>(rng.uniform() * 20),
                     static_cast<int>(rng.uniform() * 20)});
  const float spacing = 0.05f;
  const std::vector<CubeElement> cubes = cubesOn(spacing, cells);
  const auto lattice = LvoxelLattice::of(cubes);
  ASSERT_TRUE(lattice);
  const Bounds3 box = lattice->bounds();
  size_t visits = 0;
  for (int r = 0; r < 2000; ++r) {
    // From inside and from outside the lattice, some along an axis, some stopped early.
    const Vec3 o =
        box.lo + (box.hi - box.lo) * Vec3(1.4f * rng.uniform() - 0.2f, 1.4f * rng.uniform() - 0.2f,
                                          1.4f * rng.uniform() - 0.2f);
    Vec3 d = uniformSphere(rng.uniform(), rng.uniform());
    if (r % 10 == 0) d = Vec3(0.0f, r % 20 == 0 ? 1.0f : -1.0f, 0.0f);
    const Ray ray{o, d, r % 3 == 0 ? 0.1f : 0.0f, r % 4 == 0 ? 0.4f : kInf};
    const float end = r % 5 == 0 ? 0.3f : kInf;
    std::vector<std::pair<float, uint32_t>> want, got;
    for (uint32_t i = 0; i < cubes.size(); ++i) {
      float t0, t1;
      if (intersectCube(ray, cubes[i].centre, cubes[i].halfSize, t0, t1) && t0 <= end &&
          t1 - t0 > 1e-5f)
        want.push_back({t0, i});
    }
    std::sort(want.begin(), want.end());
    lattice->march(ray, end, [&](const uint32_t* list) {
      for (const uint32_t i : listOf(list)) {
        float t0, t1;
        if (intersectCube(ray, cubes[i].centre, cubes[i].halfSize, t0, t1) && t0 <= end &&
            t1 - t0 > 1e-5f)
          got.push_back({t0, i});
      }
      return true;
    });
    ASSERT_EQ(got, want) << "ray " << r << " o=" << o << " d=" << d;
    visits += got.size();
  }
  EXPECT_GT(visits, 4000u);
}

TEST(LvoxelLattice, MarchStopsWhenTheVisitSaysSo) {
  const std::vector<CubeElement> cubes = cubesOn(1.0f, {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}});
  const auto lattice = LvoxelLattice::of(cubes);
  ASSERT_TRUE(lattice);
  const Ray ray{Vec3(-1.0f, -1.2f, 2.6f), Vec3(1, 0, 0), 0.0f, kInf};
  int cellsSeen = 0;
  EXPECT_FALSE(lattice->march(ray, kInf, [&](const uint32_t*) { return ++cellsSeen < 2; }));
  EXPECT_EQ(cellsSeen, 2);
  cellsSeen = 0;
  EXPECT_TRUE(lattice->march(ray, kInf, [&](const uint32_t*) { return ++cellsSeen > 0; }));
  EXPECT_EQ(cellsSeen, 3);
}

// Two cubes 300 cells apart: the lattice stores the two bricks of 8^3 cells that hold them
// and a table of its bricks, not its 27 million cells. A thousand cells apart, its table
// alone (2 million bricks) would outweigh the cubes, and there is no lattice.
TEST(LvoxelLattice, ASparseLatticeCostsItsBricks) {
  EXPECT_FALSE(LvoxelLattice::of(cubesOn(0.01f, {{0, 0, 0}, {999, 999, 999}})));
  const std::vector<CubeElement> cubes = cubesOn(0.01f, {{0, 0, 0}, {299, 299, 299}});
  const auto lattice = LvoxelLattice::of(cubes);
  ASSERT_TRUE(lattice);
  const size_t bricks = 38 * 38 * 38;
  EXPECT_LE(lattice->memoryBytes(), bricks * 4 + 2 * 512 * 4 + 2 * 4);
  // The march crosses the empty cells between them and still finds both.
  const Ray diagonal{lattice->bounds().lo - Vec3(0.001f), normalize(Vec3(1, 1, 1)), 0.0f, kInf};
  std::vector<uint32_t> seen;
  lattice->march(diagonal, kInf, [&](const uint32_t* list) {
    for (const uint32_t i : listOf(list)) seen.push_back(i);
    return true;
  });
  EXPECT_EQ(seen, (std::vector<uint32_t>{0, 1}));
}

}  // namespace
}  // namespace lvox
