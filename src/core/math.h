#pragma once
// Small vector math on top of Imath (the OpenEXR project's math library): lvox uses
// Imath's Vec3/Color3/Matrix44 and adds the few free functions renderers need.
#include <Imath/ImathColor.h>
#include <Imath/ImathMatrix.h>
#include <Imath/ImathVec.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace lvox {

using Vec2 = Imath::V2f;
using Vec3 = Imath::V3f;
using Vec3d = Imath::V3d;
using RGB = Imath::C3f;
using Mat4 = Imath::M44f;

inline constexpr float kPi = std::numbers::pi_v<float>;
inline constexpr float kInvPi = 1.0f / kPi;
inline constexpr float kInf = std::numeric_limits<float>::infinity();

inline float dot(const Vec3& a, const Vec3& b) { return a.dot(b); }
inline Vec3 cross(const Vec3& a, const Vec3& b) { return a.cross(b); }
inline float length(const Vec3& a) { return a.length(); }
inline Vec3 normalize(const Vec3& a) { return a.normalized(); }
inline Vec3 mul(const Vec3& a, const Vec3& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }

inline float maxComponent(const RGB& c) { return std::max(c.x, std::max(c.y, c.z)); }
inline float average(const RGB& c) { return (c.x + c.y + c.z) / 3.0f; }
inline RGB nonNegative(const RGB& c) {
  return {std::max(c.x, 0.0f), std::max(c.y, 0.0f), std::max(c.z, 0.0f)};
}
inline bool isBlack(const RGB& c) { return c.x == 0.0f && c.y == 0.0f && c.z == 0.0f; }
inline bool isFinite(const RGB& c) {
  return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z);
}
inline RGB exp(const RGB& c) { return {std::exp(c.x), std::exp(c.y), std::exp(c.z)}; }

struct Ray {
  Vec3 origin;
  Vec3 dir;  // unit length
  float tmin = 0.0f;
  float tmax = kInf;
  Vec3 at(float t) const { return origin + dir * t; }
};

// Right-handed orthonormal frame around a unit normal (Duff et al. 2017, branchless).
struct Frame {
  Vec3 s, t, n;
  explicit Frame(const Vec3& normal) : n(normal) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    s = Vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    t = Vec3(b, sign + n.y * n.y * a, -n.y);
  }
  Vec3 toWorld(const Vec3& v) const { return s * v.x + t * v.y + n * v.z; }
  Vec3 toLocal(const Vec3& v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
};

// Axis-aligned box.
struct Bounds3 {
  Vec3 lo{kInf, kInf, kInf};
  Vec3 hi{-kInf, -kInf, -kInf};
  void extend(const Vec3& p) {
    lo = Vec3(std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z));
    hi = Vec3(std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z));
  }
  void extend(const Bounds3& b) {
    extend(b.lo);
    extend(b.hi);
  }
  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  Vec3 diagonal() const { return hi - lo; }
  Vec3 center() const { return (lo + hi) * 0.5f; }
  bool contains(const Vec3& p) const {
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
  }
  // Slab test; returns false when the ray misses [tmin, tmax].
  bool intersect(const Ray& ray, float& t0, float& t1) const {
    t0 = ray.tmin;
    t1 = ray.tmax;
    for (int a = 0; a < 3; ++a) {
      const float inv = 1.0f / ray.dir[a];
      float tn = (lo[a] - ray.origin[a]) * inv;
      float tf = (hi[a] - ray.origin[a]) * inv;
      if (tn > tf) std::swap(tn, tf);
      t0 = std::max(t0, tn);
      t1 = std::min(t1, tf);
      if (t0 > t1) return false;
    }
    return true;
  }
};

// Points and directions under a 4x4 affine matrix stored for column vectors (p' = M p),
// the convention of scene files. Imath stores row vectors, so lvox keeps its own helpers.
struct Transform {
  float m[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};

  Vec3 point(const Vec3& p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
            m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
  }
  Vec3 vector(const Vec3& v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  // Normals transform by the inverse transpose of the linear part.
  Vec3 normal(const Vec3& n) const;
  Transform operator*(const Transform& o) const;
  Transform inverse() const;
  float determinant3() const;
  bool isIdentity() const;

  static Transform translate(const Vec3& t);
  static Transform scale(const Vec3& s);
  static Transform rotate(const Vec3& axis, float degrees);
};

}  // namespace lvox
