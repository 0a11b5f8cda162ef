// SparseGrid: the OpenVDB tree read in place (no dense copy), its interpolations, its
// majorant trees and their hierarchical walk.
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <vector>

#include "src/core/error.h"
#include "src/core/rng.h"
#include "test_util.h"
#include "volume/media/media_set.h"
#include "volume/media/vdb_loader.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

// A grid named "density" with voxel size 1 (index = world), built by `fill`, written to
// `name` in a fresh directory and loaded back.
template <class Fill>
SparseGrid gridFrom(const std::string& name, Fill fill, GridLoadReport* reportOut = nullptr) {
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("density");
  fill(*grid);
  const fs::path path = test::tempDir() / name;
  openvdb::io::File(path.string()).write({grid});
  GridLoadReport report;
  SparseGrid g = loadVdbGrid(path.string(), "density", Transform(), "media[0].grid", report);
  if (reportOut) *reportOut = report;
  return g;
}

template <class F>
SparseGrid boxGrid(const std::string& name, int n, F f) {
  return gridFrom(name, [&](openvdb::FloatGrid& grid) {
    auto acc = grid.getAccessor();
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) acc.setValue(openvdb::Coord(i, j, k), f(i, j, k));
  });
}

TEST(SparseGrid, InterpolationsReproduceLinearFields) {
  // Nearest returns the voxel; trilinear and the cubic B-spline reproduce linear functions
  // exactly (the B-spline's weights sum to 1 and have mean offset 0).
  const auto f = [](float x, float y, float z) { return 10.0f + x + 2.0f * y + 3.0f * z; };
  const SparseGrid g = boxGrid("linear.vdb", 16, [&](int i, int j, int k) {
    return f(static_cast<float>(i), static_cast<float>(j), static_cast<float>(k));
  });
  Rng rng(3, 4);
  for (int s = 0; s < 200; ++s) {
    const Vec3 p(3.0f + 9.0f * rng.uniform(), 3.0f + 9.0f * rng.uniform(),
                 3.0f + 9.0f * rng.uniform());
    EXPECT_NEAR(g.sample(p, Interpolation::Trilinear), f(p.x, p.y, p.z), 2e-4f);
    EXPECT_NEAR(g.sample(p, Interpolation::Tricubic), f(p.x, p.y, p.z), 2e-4f);
    EXPECT_EQ(g.sample(p, Interpolation::Nearest),
              f(std::floor(p.x + 0.5f), std::floor(p.y + 0.5f), std::floor(p.z + 0.5f)));
  }
}

TEST(SparseGrid, TricubicIsTheCubicBSplineOfTheVoxels) {
  // For v(i) = i^2 the cubic B-spline gives x^2 + 1/3 (sum of w_a (x + a)^2 with the
  // B-spline's variance 1/3), where trilinear gives x^2 + f (1 - f), f = frac(x): two
  // closed forms that tell the interpolations apart.
  const SparseGrid g =
      boxGrid("square.vdb", 16, [](int i, int, int) { return static_cast<float>(i * i); });
  for (float x = 3.0f; x < 12.0f; x += 0.37f) {
    const Vec3 p(x, 7.3f, 8.6f);
    const float f = x - std::floor(x);
    EXPECT_NEAR(g.sample(p, Interpolation::Tricubic), x * x + 1.0f / 3.0f, 1e-3f) << x;
    EXPECT_NEAR(g.sample(p, Interpolation::Trilinear), x * x + f * (1.0f - f), 1e-3f) << x;
  }
}

TEST(SparseGrid, OnlyActiveNonNegativeValuesAreDensity) {
  GridLoadReport report;
  const SparseGrid g = gridFrom(
      "inactive.vdb",
      [](openvdb::FloatGrid& grid) {
        auto acc = grid.getAccessor();
        acc.setValueOn(openvdb::Coord(1, 1, 1), 2.0f);
        acc.setValueOn(openvdb::Coord(2, 1, 1), -3.0f);
        acc.setValueOff(openvdb::Coord(3, 1, 1), 7.0f);  // inactive: not density
      },
      &report);
  EXPECT_EQ(g.voxel(1, 1, 1), 2.0f);
  EXPECT_EQ(g.voxel(2, 1, 1), 0.0f);
  EXPECT_EQ(g.voxel(3, 1, 1), 0.0f);
  EXPECT_EQ(report.clampedNegative, 1u);
  EXPECT_EQ(report.mostNegative, -3.0f);
  EXPECT_EQ(g.maxValue(), 2.0f);
  EXPECT_EQ(g.activeVoxels(), 2u);
}

// Two blobs of density far apart: the grid's bounding box is 4096 voxels long.
SparseGrid twoBlobs() {
  return gridFrom("blobs.vdb", [](openvdb::FloatGrid& grid) {
    auto acc = grid.getAccessor();
    for (int blob = 0; blob < 2; ++blob)
      for (int k = 0; k < 12; ++k)
        for (int j = 0; j < 12; ++j)
          for (int i = 0; i < 12; ++i)
            acc.setValue(openvdb::Coord(blob * 4096 + i, j, k),
                         1.0f + static_cast<float>(((i * 7 + j * 3 + k) % 5) * (blob + 1)));
  });
}

TEST(SparseGrid, MajorantsBoundTheValuesAndZeroOutsideTheSpans) {
  const SparseGrid g = twoBlobs();
  Rng rng(7, 8);
  std::vector<MajorantSpan> spans;
  for (int r = 0; r < 200; ++r) {
    Ray ray;
    ray.origin =
        Vec3(-40.0f, 6.0f + 8.0f * (rng.uniform() - 0.5f), 6.0f + 8.0f * (rng.uniform() - 0.5f));
    // Mostly along x (through both blobs), some steep.
    ray.dir = normalize(Vec3(1.0f, 0.2f * (rng.uniform() - 0.5f), 0.2f * (rng.uniform() - 0.5f)));
    if (r % 4 == 0) ray.dir = normalize(Vec3(0.3f, rng.uniform() - 0.5f, rng.uniform() - 0.5f));
    const float tmax = 4200.0f;
    for (MajorantLevel level :
         {MajorantLevel::kBlock, MajorantLevel::kNode, MajorantLevel::kGlobal}) {
      spans.clear();
      g.majorantSpans(ray, 0.0f, tmax, level, spans);
      for (size_t s = 0; s < spans.size(); ++s) {
        ASSERT_LT(spans[s].t0, spans[s].t1);
        if (s > 0) {
          ASSERT_LE(spans[s - 1].t1, spans[s].t0 + 1e-4f);
        }
      }
      // Every interpolated value along the ray is below the span's majorant, and zero
      // between spans.
      size_t s = 0;
      for (float t = 0.0f; t < tmax; t += 0.25f) {
        while (s < spans.size() && spans[s].t1 <= t) ++s;
        const bool inside = s < spans.size() && spans[s].t0 <= t;
        for (Interpolation interp :
             {Interpolation::Nearest, Interpolation::Trilinear, Interpolation::Tricubic}) {
          const float v = g.sample(ray.at(t), interp);
          if (inside)
            ASSERT_LE(v, spans[s].majorant * (1.0f + 1e-5f)) << t;
          else
            ASSERT_EQ(v, 0.0f) << "t " << t << " level " << static_cast<int>(level);
        }
      }
    }
  }
}

TEST(SparseGrid, TheWalkJumpsOverEmptyNodes) {
  const SparseGrid g = twoBlobs();
  Ray ray;
  ray.origin = Vec3(-40.0f, 6.0f, 6.0f);
  ray.dir = Vec3(1.0f, 0.0f, 0.0f);
  std::vector<MajorantSpan> spans;
  uint64_t cells = 0;
  g.majorantSpans(ray, 0.0f, 5000.0f, MajorantLevel::kBlock, spans, &cells);
  // The blobs and their dilation: 4 blocks each; in between, 4096 voxels (512 blocks) of
  // nothing cost a few steps over empty nodes of 8 and 128 blocks: about 53 of 516.
  ASSERT_EQ(spans.size(), 2u);
  EXPECT_NEAR(spans[0].t0, 40.0f - 8.5f, 1e-3f);
  EXPECT_NEAR(spans[1].t1, 40.0f + 4096.0f + 16.0f + 7.5f, 1e-2f);
  EXPECT_LT(cells, 64u);
  std::vector<std::pair<float, float>> intervals;
  g.intervals(ray, 0.0f, 5000.0f, intervals);
  ASSERT_EQ(intervals.size(), 2u);
  EXPECT_EQ(intervals[0].first, spans[0].t0);
  EXPECT_EQ(intervals[1].second, spans[1].t1);
}

// Every kind of place a value can live, looked up through the lower-node index and the
// per-thread leaf caches, against OpenVDB's own lookup of the same tree: voxels in several
// lower nodes on both sides of the origin, inactive and negative voxels (0), tiles of a
// lower node (8^3), of an upper node (128^3) and of the root (4096^3), and voxels beyond
// the index's reach of 2^27, which it leaves to the tree.
// A grid filled by `fill` both as OpenVDB holds it and as lvox reads it from a file, and what
// a lookup should give: the active, non-negative value (else 0).
struct Filled {
  openvdb::FloatGrid::Ptr reference;
  SparseGrid grid;
  float expected(const openvdb::Coord& c) const {
    float v = 0.0f;
    return reference->tree().probeValue(c, v) && v > 0.0f ? v : 0.0f;
  }
};

template <class Fill>
Filled filled(const std::string& name, Fill fill) {
  openvdb::initialize();
  auto reference = openvdb::FloatGrid::create(0.0f);
  fill(*reference);
  return {reference, gridFrom(name, fill)};
}

TEST(SparseGrid, LookupsFindEveryKindOfValueOpenVdbHolds) {
  using openvdb::Coord;
  const auto fill = [](openvdb::FloatGrid& grid) {
    auto acc = grid.getAccessor();
    Rng rng(11, 12);
    for (int n = 0; n < 400; ++n) {
      const Coord c(static_cast<int>(rng.uniform() * 600.0f) - 300,
                    static_cast<int>(rng.uniform() * 300.0f) - 150,
                    static_cast<int>(rng.uniform() * 300.0f) - 150);
      acc.setValue(c, 0.1f + rng.uniform());
    }
    acc.setValue(Coord(5, 5, 5), -2.0f);    // clamped to 0
    acc.setValueOff(Coord(6, 5, 5), 3.0f);  // inactive: 0
    grid.tree().addTile(1, Coord(64, 64, 64), 0.25f, true);
    grid.tree().addTile(2, Coord(1024, 0, 0), 0.5f, true);
    grid.tree().addTile(3, Coord(-8192, 0, 0), 0.75f, true);
    const int far = (1 << 27) + 100;
    acc.setValue(Coord(far, 3, -far), 1.5f);
  };
  const Filled kinds = filled("kinds.vdb", fill);
  const SparseGrid& g = kinds.grid;
  EXPECT_FALSE(g.hasLeafTable());  // its active box spans 2^27 voxels: through the index
  const auto expected = [&](const Coord& c) { return kinds.expected(c); };
  const int far = (1 << 27) + 100;
  std::vector<Coord> probes = {Coord(5, 5, 5),          Coord(6, 5, 5),         Coord(66, 70, 71),
                               Coord(1100, 60, 30),     Coord(-5000, 17, 2000), Coord(far, 3, -far),
                               Coord(far + 1, 3, -far), Coord(1 << 28, 0, 0)};
  Rng rng(5, 6);
  for (auto v = kinds.reference->tree().cbeginLeaf(); v; ++v)  // every voxel in a leaf
    for (auto on = v->cbeginValueOn(); on; ++on) probes.push_back(on.getCoord());
  for (int n = 0; n < 20000; ++n)  // random places, most in empty space or tiles
    probes.emplace_back(static_cast<int>(rng.uniform() * 20000.0f) - 10000,
                        static_cast<int>(rng.uniform() * 600.0f) - 300,
                        static_cast<int>(rng.uniform() * 600.0f) - 300);
  int nonZero = 0;
  for (const Coord& c : probes) {
    ASSERT_EQ(g.voxel(c.x(), c.y(), c.z()), expected(c)) << c;
    nonZero += expected(c) > 0.0f;
  }
  EXPECT_GT(nonZero, 1000);  // the tiles and voxels were reached, not only empty space
}

// The same through the flat leaf table (a compact grid: a dense block and scattered
// voxels): leaf buffers, regions of zeros, a leaf-sized tile of another value (left to the
// index), places outside the active box, and stencils across leaves.
TEST(SparseGrid, LookupsThroughTheLeafTableFindWhatOpenVdbHolds) {
  using openvdb::Coord;
  const auto fill = [](openvdb::FloatGrid& grid) {
    auto acc = grid.getAccessor();
    for (int i = 0; i < 48; ++i)
      for (int j = 0; j < 48; ++j)
        for (int k = 0; k < 48; ++k) acc.setValue(Coord(i, j, k), 0.5f + 0.01f * float(i ^ j ^ k));
    Rng rng(21, 22);
    for (int n = 0; n < 100; ++n)
      acc.setValue(Coord(static_cast<int>(rng.uniform() * 160.0f) - 80,
                         static_cast<int>(rng.uniform() * 160.0f) - 80,
                         static_cast<int>(rng.uniform() * 160.0f) - 80),
                   0.1f + rng.uniform());
    acc.setValue(Coord(-5, -5, -5), -2.0f);  // clamped to 0
    grid.tree().addTile(1, Coord(-64, 40, 40), 0.25f, true);
  };
  const Filled table = filled("table.vdb", fill);
  const SparseGrid& g = table.grid;
  ASSERT_TRUE(g.hasLeafTable());
  const auto expected = [&](const Coord& c) { return table.expected(c); };
  Rng rng(7, 8);
  int nonZero = 0;
  for (int n = 0; n < 40000; ++n) {  // inside and around the active box
    const Coord c(static_cast<int>(rng.uniform() * 240.0f) - 120,
                  static_cast<int>(rng.uniform() * 240.0f) - 120,
                  static_cast<int>(rng.uniform() * 240.0f) - 120);
    ASSERT_EQ(g.voxel(c.x(), c.y(), c.z()), expected(c)) << c;
    nonZero += expected(c) > 0.0f;
  }
  EXPECT_GT(nonZero, 200);                 // the dense block is 0.8 % of the cube: about 330 hits
  EXPECT_EQ(g.voxel(-60, 44, 44), 0.25f);  // the tile
  // Trilinear lookups across leaf faces equal the blend of OpenVDB's voxels.
  for (int n = 0; n < 2000; ++n) {
    const Vec3 p(rng.uniform() * 56.0f - 4.0f, rng.uniform() * 56.0f - 4.0f,
                 rng.uniform() * 56.0f - 4.0f);
    const int i = static_cast<int>(std::floor(p.x)), j = static_cast<int>(std::floor(p.y)),
              k = static_cast<int>(std::floor(p.z));
    const float tx = p.x - float(i), ty = p.y - float(j), tz = p.z - float(k);
    double blend = 0.0;
    for (int c = 0; c < 8; ++c) {
      const int dx = c & 1, dy = c >> 1 & 1, dz = c >> 2;
      blend += double(expected(Coord(i + dx, j + dy, k + dz))) * (dx ? tx : 1 - tx) *
               (dy ? ty : 1 - ty) * (dz ? tz : 1 - tz);
    }
    ASSERT_NEAR(g.sampleIndex(p, Interpolation::Trilinear), blend, 1e-5) << p;
  }
}

// A voxel at -2^31 made the bounds' stencil padding overflow int (found by fuzzing): grids
// reaching beyond +-2^29 are refused, naming the index.
TEST(SparseGrid, VoxelsBeyondTheIndexedRangeAreRefused) {
  for (const int at : {(1 << 29) + 8, -2147483647 - 1}) {
    try {
      gridFrom("far.vdb", [at](openvdb::FloatGrid& grid) {
        grid.tree().setValue(openvdb::Coord(0, at, 0), 1.0f);
      });
      ADD_FAILURE() << at << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("at index " + std::to_string(at) + " (axis 1)"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_EQ(gridFrom("near.vdb",
                     [](openvdb::FloatGrid& grid) {
                       grid.tree().setValue(openvdb::Coord(0, (1 << 29) - 8, 0), 1.0f);
                     })
                .activeVoxels(),
            1u);
}

TEST(SparseGrid, AHugeTileCostsItsTileNotItsVoxels) {
  // One active tile of 4096^3 voxels (a 2 KB file): 6.9e10 voxels that a dense copy could
  // never hold. The values and the majorant trees stay tiles.
  const SparseGrid g = gridFrom("tile.vdb", [](openvdb::FloatGrid& grid) {
    grid.tree().fill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(4095)), 0.5f, true);
  });
  EXPECT_EQ(g.activeVoxels(), 4096ull * 4096ull * 4096ull);
  EXPECT_EQ(g.sample(Vec3(2000.3f, 17.2f, 3000.9f), Interpolation::Tricubic), 0.5f);
  EXPECT_LT(g.memoryBytes(), 64u << 20);
  Ray ray;
  ray.origin = Vec3(-10.0f, 100.0f, 100.0f);
  ray.dir = Vec3(1.0f, 0.0f, 0.0f);
  std::vector<MajorantSpan> spans;
  uint64_t cells = 0;
  g.majorantSpans(ray, 0.0f, 1e5f, MajorantLevel::kBlock, spans, &cells);
  ASSERT_EQ(spans.size(), 1u);
  EXPECT_EQ(spans[0].majorant, 0.5f);
  EXPECT_LT(cells, 100u);
}

TEST(SparseGrid, TheMajorantLevelFollowsTheCost) {
  const SparseGrid g = twoBlobs();
  // Thin: tentative collisions are rare, so the walk's steps dominate: one global span.
  EXPECT_EQ(g.cheapestMajorantLevel(1e-4f, Interpolation::Trilinear), MajorantLevel::kGlobal);
  // Thick: every null collision is a lookup, so the tightest majorant pays.
  EXPECT_EQ(g.cheapestMajorantLevel(100.0f, Interpolation::Trilinear), MajorantLevel::kBlock);
  // Deterministic.
  EXPECT_EQ(g.cheapestMajorantLevel(1.0f, Interpolation::Tricubic),
            g.cheapestMajorantLevel(1.0f, Interpolation::Tricubic));
}

TEST(SparseGrid, ThreadsAndGridsShareNoAccessor) {
  // Several grids read alternately from many threads (more grids than accessor slots per
  // thread) give exactly the single-threaded values.
  std::vector<SparseGrid> grids;
  for (int n = 0; n < 6; ++n)
    grids.push_back(boxGrid("g" + std::to_string(n) + ".vdb", 20, [n](int i, int j, int k) {
      return static_cast<float>((i * 31 + j * 17 + k * 7 + n * 13) % 23);
    }));
  std::vector<Vec3> points(4000);
  Rng rng(9, 10);
  for (Vec3& p : points) p = Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 20.0f;
  std::vector<float> serial(points.size()), parallel(points.size());
  for (size_t i = 0; i < points.size(); ++i)
    serial[i] = grids[i % grids.size()].sample(points[i], Interpolation::Tricubic);
  tbb::parallel_for(size_t{0}, points.size(), [&](size_t i) {
    parallel[i] = grids[i % grids.size()].sample(points[i], Interpolation::Tricubic);
  });
  EXPECT_EQ(serial, parallel);
}

}  // namespace
}  // namespace lvox

namespace lvox {
namespace {

// The memory budget sees a grid's tree before OpenVDB reads it: the file's own statistics
// (file_mem_bytes, written by OpenVDB with every grid) are reserved first, so a grid
// larger than the budget is refused with one line naming the file, the field and the grid,
// and one within it is reserved at its size.
TEST(SparseGrid, TheBudgetSeesTheTreeBeforeItIsRead) {
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("density");
  auto acc = grid->getAccessor();
  for (int k = 0; k < 160; ++k)  // 160^3 voxels: about 16 MB of leaves
    for (int j = 0; j < 160; ++j)
      for (int i = 0; i < 160; ++i) acc.setValue(openvdb::Coord(i, j, k), 0.5f);
  const size_t treeBytes = grid->memUsage();
  const fs::path path = test::tempDir() / "big.vdb";
  openvdb::io::File(path.string()).write({grid});
  std::vector<uint64_t> seen;
  GridLoadReport report;
  loadVdbGrid(path.string(), "density", Transform(), "media[0].grid", report,
              [&](uint64_t bytes) { seen.push_back(bytes); });
  ASSERT_EQ(seen.size(), 1u);
  // OpenVDB's figure for the tree it wrote: what the loaded tree takes, within 10 %.
  EXPECT_NEAR(static_cast<double>(seen[0]), static_cast<double>(treeBytes),
              0.1 * static_cast<double>(treeBytes));
  EXPECT_NEAR(static_cast<double>(report.treeBytes), static_cast<double>(treeBytes),
              0.1 * static_cast<double>(treeBytes));

  MediumDesc d;
  d.type = MediumType::Vdb;
  d.file = path.string();
  d.grid = "density";
  d.field = "media[0]";
  std::vector<std::string> warnings;
  MemoryBudget small(8u << 20);
  try {
    MediaSet::build({d}, Interpolation::Trilinear, warnings, &small);
    FAIL() << "a 16 MB grid passed an 8 MB budget";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("big.vdb: media[0].grid: grid 'density' as OpenVDB holds it"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("--max-memory"), std::string::npos) << message;
  }
  EXPECT_EQ(small.reserved(), 0u);
  MemoryBudget enough(1u << 30);
  const MediaSet media = MediaSet::build({d}, Interpolation::Trilinear, warnings, &enough);
  EXPECT_EQ(enough.reserved(), seen[0]);
  EXPECT_LE(enough.reserved(), media.memoryBytes());  // the rest are the majorant trees

  // Without statistics: the voxel count x 4 bytes, else the file size.
  EXPECT_EQ(estimatedTreeBytes(1000, 10, 7), 1000u);
  EXPECT_EQ(estimatedTreeBytes(-1, 10, 7), 40u);
  EXPECT_EQ(estimatedTreeBytes(-1, -1, 7), 7u);
}

}  // namespace
}  // namespace lvox
