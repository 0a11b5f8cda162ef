#pragma once
// Small meshes and media shared by the point-cloud tests.
#include <cstdint>
#include <vector>

#include "src/world/world.h"

namespace lvox::test {

// Appends the quad a-b-c-d (two triangles) with material m.
inline void addQuad(TriangleMesh& mesh, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                    uint32_t m) {
  const auto base = static_cast<uint32_t>(mesh.positions.size());
  mesh.positions.insert(mesh.positions.end(), {a, b, c, d});
  mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  mesh.triangleMaterial.insert(mesh.triangleMaterial.end(), {m, m});
}

// The six faces of the box [lo, hi], normals pointing inward.
inline void addBox(TriangleMesh& mesh, const Vec3& lo, const Vec3& hi, uint32_t m) {
  const Vec3 p[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z},
                     {lo.x, hi.y, lo.z}, {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z},
                     {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  addQuad(mesh, p[0], p[1], p[2], p[3], m);  // z = lo
  addQuad(mesh, p[4], p[7], p[6], p[5], m);  // z = hi
  addQuad(mesh, p[0], p[4], p[5], p[1], m);  // y = lo
  addQuad(mesh, p[3], p[2], p[6], p[7], m);  // y = hi
  addQuad(mesh, p[0], p[3], p[7], p[4], m);  // x = lo
  addQuad(mesh, p[1], p[5], p[6], p[2], m);  // x = hi
}

inline double meshArea(const TriangleMesh& mesh) { return mesh.area(); }

// UV sphere: many small, differently sized triangles.
inline void addSphere(TriangleMesh& mesh, const Vec3& c, float r, int rings, int segments,
                      uint32_t m) {
  const auto base = static_cast<uint32_t>(mesh.positions.size());
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const float th = kPi * static_cast<float>(i) / static_cast<float>(rings);
      const float ph = 2.0f * kPi * static_cast<float>(j) / static_cast<float>(segments);
      mesh.positions.push_back(
          c + Vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)) * r);
    }
  auto idx = [&](int i, int j) {
    return base + static_cast<uint32_t>(i * segments + j % segments);
  };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = idx(i, j), b = idx(i + 1, j), cc = idx(i + 1, j + 1), d = idx(i, j + 1);
      if (i > 0) {
        mesh.indices.insert(mesh.indices.end(), {a, b, d});
        mesh.triangleMaterial.push_back(m);
      }
      if (i < rings - 1) {
        mesh.indices.insert(mesh.indices.end(), {b, cc, d});
        mesh.triangleMaterial.push_back(m);
      }
    }
}

// A medium for sampleLvoxels: homogeneous coefficients inside a box.
struct BoxMedium {
  Bounds3 box;
  RGB sigmaA{0, 0, 0}, sigmaS{0, 0, 0};
  std::vector<Bounds3> active;
  BoxMedium(const Vec3& lo, const Vec3& hi, const RGB& a, const RGB& s) : sigmaA(a), sigmaS(s) {
    box.lo = lo;
    box.hi = hi;
    active.push_back(box);
  }
  Bounds3 bounds() const { return box; }
  const std::vector<Bounds3>& activeBoxes() const { return active; }
  void coefficients(const Vec3& p, RGB& a, RGB& s) const {
    const bool in = box.contains(p);
    a = in ? sigmaA : RGB(0.0f);
    s = in ? sigmaS : RGB(0.0f);
  }
};

}  // namespace lvox::test
