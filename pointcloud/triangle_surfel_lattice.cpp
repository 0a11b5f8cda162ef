#include "pointcloud/triangle_surfel_lattice.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace lvox {
namespace {

// Divisions of an edge direction at most: the table's 16 bits, far past what any surfel
// spacing a scene can afford asks for (the slivers' cap keeps a triangle's points near its
// surfels' count).
constexpr float kMaxDivisions = 65535.0f;

uint32_t divisionsFor(float length, float step) {
  return static_cast<uint32_t>(std::clamp(std::ceil(length / step), 1.0f, kMaxDivisions));
}

// Triangular lattice of m divisions: row i holds the points j = 0 .. m - i.
size_t triangularIndex(uint32_t m, uint32_t i, uint32_t j) {
  return static_cast<size_t>(i) * (2 * static_cast<size_t>(m) + 3 - i) / 2 + j;
}

}  // namespace

size_t TriangleSurfelLattice::Shape::points() const {
  return parallelogram ? static_cast<size_t>(m1 + 1) * (m2 + 1)
                       : static_cast<size_t>(m1 + 1) * (m1 + 2) / 2;
}

TriangleSurfelLattice::Shape TriangleSurfelLattice::shapeOf(const Vec3& a, const Vec3& b,
                                                            const Vec3& c, float step) {
  const std::array<float, 3> opposite{length(c - b), length(a - c), length(b - a)};
  // An equilateral triangle of area A has sides sqrt(4 A / sqrt(3)).
  const float area = 0.5f * length(cross(b - a, c - a));
  const float cap = 4.0f * std::max(1.0f, std::ceil(std::sqrt(2.3094f * area) / step)) * step;
  const auto widest =
      static_cast<uint8_t>(std::max_element(opposite.begin(), opposite.end()) - opposite.begin());
  Shape triangular;
  triangular.m1 = triangular.m2 = divisionsFor(std::min(opposite[widest], cap), step);
  Shape parallelogram;
  parallelogram.parallelogram = true;
  parallelogram.apex = widest;  // the widest angle lies opposite the longest edge
  parallelogram.m1 = divisionsFor(std::min(opposite[(widest + 2) % 3], cap), step);
  parallelogram.m2 = divisionsFor(std::min(opposite[(widest + 1) % 3], cap), step);
  return parallelogram.points() < triangular.points() ? parallelogram : triangular;
}

size_t TriangleSurfelLattice::pointsFor(const TriangleMesh& mesh, float step) {
  size_t total = 0;
  for (size_t t = 0; t < mesh.triangleCount(); ++t)
    total += shapeOf(mesh.vertex(t, 0), mesh.vertex(t, 1), mesh.vertex(t, 2), step).points();
  return total;
}

size_t TriangleSurfelLattice::bytesFor(size_t points, size_t triangles) {
  return points * sizeof(uint32_t) + triangles * sizeof(Triangle);
}

TriangleSurfelLattice::TriangleSurfelLattice(const TriangleMesh& mesh, const SurfelLookup& lookup,
                                             float step)
    : surfels_(lookup.surfels()), cell_(lookup.cell()) {
  const size_t n = mesh.triangleCount();
  triangles_.resize(n);
  size_t total = 0;
  for (size_t t = 0; t < n; ++t) {
    const Shape shape = shapeOf(mesh.vertex(t, 0), mesh.vertex(t, 1), mesh.vertex(t, 2), step);
    if (total + shape.points() > std::numeric_limits<uint32_t>::max())
      throw std::length_error("the surfel lattice needs more than 2^32 points");
    triangles_[t] =
        Triangle{static_cast<uint32_t>(total), static_cast<uint16_t>(shape.m1),
                 static_cast<uint16_t>(shape.m2), shape.parallelogram ? shape.apex : kTriangular};
    total += shape.points();
  }
  surfel_.assign(total, kNone);
  if (!surfels_ || lookup.empty()) return;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 64), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t < r.end(); ++t) {
      const Triangle& tri = triangles_[t];
      const Vec3 v0 = mesh.vertex(t, 0);
      const Vec3 face = cross(mesh.vertex(t, 1) - v0, mesh.vertex(t, 2) - v0);
      // A triangle without area is never hit; its points keep a valid normal all the same.
      const Vec3 normal = dot(face, face) > 0.0f ? normalize(face) : Vec3(0, 0, 1);
      const bool triangular = tri.apex == kTriangular;
      const int apex = triangular ? 0 : tri.apex;
      const Vec3 o = mesh.vertex(t, apex);
      const Vec3 e1 = mesh.vertex(t, (apex + 1) % 3) - o, e2 = mesh.vertex(t, (apex + 2) % 3) - o;
      const float inv1 = 1.0f / static_cast<float>(tri.m1),
                  inv2 = 1.0f / static_cast<float>(tri.m2);
      uint32_t* out = surfel_.data() + tri.first;
      for (uint32_t i = 0; i <= tri.m1; ++i)
        for (uint32_t j = 0; j <= (triangular ? tri.m1 - i : tri.m2); ++j) {
          const Vec3 p =
              o + e1 * (static_cast<float>(i) * inv1) + e2 * (static_cast<float>(j) * inv2);
          const long s = lookup.nearest(p, normal);
          *out++ = s >= 0 ? static_cast<uint32_t>(s) : kNone;
        }
    }
  });
}

long TriangleSurfelLattice::nearest(const SurfaceHit& hit) const {
  if (!surfels_ || hit.triangle >= triangles_.size()) return -1;
  const Triangle& tri = triangles_[hit.triangle];
  const uint32_t* points = surfel_.data() + tri.first;
  // The four corners of the lattice cell holding the hit: (i, j), (i + 1, j), (i, j + 1),
  // (i + 1, j + 1), in lattice coordinates (u m1, v m2) of the hit's barycentrics.
  // Clamped into the triangle (a NaN to 0: the lattice index must stay in range).
  auto unit = [](float b) { return std::min(1.0f, std::max(0.0f, b)); };
  const float b1 = unit(hit.b1), b2 = unit(hit.b2);
  std::array<uint32_t, 4> corners;
  if (tri.apex == kTriangular) {
    const uint32_t m = tri.m1;
    const float fm = static_cast<float>(m);
    const uint32_t i = std::min(static_cast<uint32_t>(b1 * fm), m - 1);
    const uint32_t j = std::min(static_cast<uint32_t>(b2 * fm), m - 1 - i);
    // Next to the third edge the cell is the lattice's triangle (i, j), (i + 1, j), (i, j + 1).
    corners = {points[triangularIndex(m, i, j)], points[triangularIndex(m, i + 1, j)],
               points[triangularIndex(m, i, j + 1)],
               i + j + 2 <= m ? points[triangularIndex(m, i + 1, j + 1)] : kNone};
  } else {
    // The barycentrics of the apex's two neighbours, from those of vertices 1 and 2.
    const float w[3] = {std::max(0.0f, 1.0f - b1 - b2), b1, b2};
    const float u = w[(tri.apex + 1) % 3], v = w[(tri.apex + 2) % 3];
    const uint32_t i = std::min(static_cast<uint32_t>(u * static_cast<float>(tri.m1)), tri.m1 - 1u);
    const uint32_t j = std::min(static_cast<uint32_t>(v * static_cast<float>(tri.m2)), tri.m2 - 1u);
    const size_t row = tri.m2 + 1u;
    const uint32_t* p = points + i * row + j;
    corners = {p[0], p[row], p[1], p[row + 1]};
  }
  NearestSurfelChoice choice(*surfels_, hit.point, hit.normal);
  for (uint32_t s : corners)
    if (s != kNone) choice.consider(s);
  return choice.result(cell_);
}

size_t TriangleSurfelLattice::memoryBytes() const {
  return triangles_.capacity() * sizeof(Triangle) + surfel_.capacity() * sizeof(uint32_t);
}

}  // namespace lvox
