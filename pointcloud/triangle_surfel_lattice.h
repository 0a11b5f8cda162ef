#pragma once
// The surfel that stands for a ray-traced hit, found from the triangle hit: on every
// triangle a lattice of points holds the SurfelLookup's answer at each point (computed
// once, when the cloud is built), and a hit chooses among the answers at the four corners
// of the lattice cell it falls in, by the lookup's own metric (NearestSurfelChoice). Two
// table reads and four candidates, where the lookup searches up to 27 grid cells: a traced
// gather ray's surfel costs a fraction of its Embree ray (issue 13, item 4).
//
// The answer is the lookup's wherever the surfel nearest to the hit is nearest to one of
// the cell's corners too, which is most of the time for a lattice as fine as the surfels;
// at the lattice's points it is the lookup's always, for hits on the side the triangle's
// normal faces (the corners' answers are taken for that side; the hit's own side weighs
// the four candidates). docs/pointcloud.md, "The triangle lattice", gives how often and
// what it costs in the image.
//
// A triangle's lattice is one of two shapes, whichever has fewer points: the triangular
// lattice of m divisions of every edge (points (i, j), i + j <= m, at barycentrics
// (i / m, j / m)), or the parallelogram spanned by the two edges at the triangle's widest
// angle, divided m1 and m2 times, whose points past the third edge stand for the hits near
// it. The halves of long rectangles need far fewer points the second way.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pointcloud/surfel_lookup.h"
#include "src/geometry/ray_tracer.h"
#include "src/world/world.h"

namespace lvox {

class TriangleSurfelLattice {
 public:
  // One triangle's lattice: its points lie at most `step` apart along the triangle's edges,
  // except on slivers, which get the divisions of a triangle of their area with equal sides,
  // four times over at most (their long edges would cost far more points than their
  // surfels).
  struct Shape {
    bool parallelogram = false;
    uint8_t apex = 0;         // parallelogram: the vertex (0-2) whose two edges span it
    uint32_t m1 = 1, m2 = 1;  // divisions along apex -> apex + 1 and apex -> apex + 2
                              // (triangular: m1 == m2 == m, from vertex 0)
    size_t points() const;
  };
  static Shape shapeOf(const Vec3& a, const Vec3& b, const Vec3& c, float step);
  // Lattice points over the whole mesh, and the bytes a lattice of that many points over
  // that many triangles holds (before it is built, for the memory budget).
  static size_t pointsFor(const TriangleMesh& mesh, float step);
  static size_t bytesFor(size_t points, size_t triangles);

  TriangleSurfelLattice() = default;
  // `lookup` answers for the lattice's points; it is read only while the lattice is built.
  // Throws std::length_error past 2^32 - 1 points.
  TriangleSurfelLattice(const TriangleMesh& mesh, const SurfelLookup& lookup, float step);

  // The surfel standing for the surface at `hit` (its triangle, barycentrics, point and
  // normal facing the ray), or -1 when none is near.
  long nearest(const SurfaceHit& hit) const;
  size_t points() const { return surfel_.size(); }
  size_t memoryBytes() const;

 private:
  static constexpr uint32_t kNone = ~0u;
  static constexpr uint8_t kTriangular = 3;
  struct Triangle {
    uint32_t first = 0;  // its lattice's first point in surfel_
    uint16_t m1 = 1, m2 = 1;
    uint8_t apex = kTriangular;  // 0-2: a parallelogram at that vertex
  };
  const CloudSurfels* surfels_ = nullptr;
  float cell_ = 1.0f;
  std::vector<Triangle> triangles_;
  std::vector<uint32_t> surfel_;  // per lattice point, row by row: the lookup's answer or kNone
};

}  // namespace lvox
