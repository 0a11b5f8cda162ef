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
    if (d2 < bestAligned && std::abs(dot(s.normal(i), n)) >= 0.5f) {
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

TEST(SurfelLookup, PassingCellsOverNeverChangesTheAnswer) {
  // Surfels scattered in a box, some on a lattice of the cell size (exact ties of the
  // metric), queried at random points with random normals and at lattice points.
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
    set.position[i] = p;
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
    const long expected = bruteForceNearest(s, cell, p, n);
    ASSERT_EQ(lookup.nearest(p, n), expected) << k << " at " << p;
    found += expected >= 0;
  }
  EXPECT_GT(found, 15000);  // most queries have an answer: the test is not vacuous
}

}  // namespace
}  // namespace lvox
