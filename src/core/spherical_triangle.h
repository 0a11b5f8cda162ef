#pragma once
// A triangle as seen from a point: the spherical triangle of the directions to it, its
// solid angle, and directions sampled uniformly within it (Arvo 1995, "Stratified
// Sampling of Spherical Triangles"). Sampling an emitter by solid angle keeps a light
// sample bounded however close the point is, where sampling it by area gives cos/r^2,
// whose variance diverges for points near the emitter (a medium touching a lamp).
// In double: the formulas subtract nearly equal terms for small triangles.
#include <algorithm>
#include <cmath>

#include "src/core/math.h"

namespace lvox {

class SphericalTriangle {
 public:
  // The triangle (a, b, c) seen from p.
  SphericalTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c)
      : a_(unit(a - p)), b_(unit(b - p)), c_(unit(c - p)) {
    // Van Oosterom & Strackee: tan(solid angle / 2) = |a . (b x c)| / (1 + a.b + b.c + c.a).
    const double det = std::abs(dot3(a_, cross3(b_, c_)));
    const double denom = 1.0 + dot3(a_, b_) + dot3(b_, c_) + dot3(c_, a_);
    solidAngle_ = 2.0 * std::atan2(det, denom);
    // The angle at vertex a between the great circles to b and to c.
    const D3 nab = cross3(a_, b_), nac = cross3(a_, c_);
    const double lab = std::sqrt(dot3(nab, nab)), lac = std::sqrt(dot3(nac, nac));
    alpha_ = lab > 0.0 && lac > 0.0 ? std::acos(std::clamp(dot3(nab, nac) / (lab * lac), -1.0, 1.0))
                                    : 0.0;
  }

  // Steradians (0 when p lies in the triangle's plane or the triangle is degenerate).
  double solidAngle() const { return solidAngle_; }

  // A unit direction uniformly distributed over the spherical triangle (pdf 1 / solid
  // angle) for (u1, u2) uniform in [0,1)^2. The map is continuous and area-preserving, so
  // stratified (u1, u2) give stratified directions.
  Vec3 sample(double u1, double u2) const {
    // Arvo: the sub-triangle (a, b, c') of area u1 * solidAngle fixes c' on the arc a-c ...
    const double area = u1 * solidAngle_;
    const double s = std::sin(area - alpha_), t = std::cos(area - alpha_);
    const double cosAlpha = std::cos(alpha_), sinAlpha = std::sin(alpha_);
    const double u = t - cosAlpha;
    const double v = s + sinAlpha * dot3(a_, b_);
    const double q =
        std::clamp(((v * t - u * s) * cosAlpha - v) / ((v * s + u * t) * sinAlpha), -1.0, 1.0);
    const D3 cp = add3(scale3(a_, q), scale3(orthogonal(c_, a_), std::sqrt(1.0 - q * q)));
    // ... then the direction lies on the arc b-c', at cos z from b.
    const double z = 1.0 - u2 * (1.0 - dot3(cp, b_));
    const D3 w =
        add3(scale3(b_, z), scale3(orthogonal(cp, b_), std::sqrt(std::max(0.0, 1.0 - z * z))));
    return Vec3(static_cast<float>(w.x), static_cast<float>(w.y), static_cast<float>(w.z));
  }

 private:
  struct D3 {
    double x, y, z;
  };
  static D3 unit(const Vec3& v) {
    const D3 d{v.x, v.y, v.z};
    const double l = std::sqrt(dot3(d, d));
    return l > 0.0 ? scale3(d, 1.0 / l) : D3{0.0, 0.0, 0.0};
  }
  static double dot3(const D3& a, const D3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
  static D3 cross3(const D3& a, const D3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  }
  static D3 scale3(const D3& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
  static D3 add3(const D3& a, const D3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  // The unit vector along the part of v orthogonal to the unit vector n (0 if none).
  static D3 orthogonal(const D3& v, const D3& n) {
    const D3 o = add3(v, scale3(n, -dot3(v, n)));
    const double l = std::sqrt(dot3(o, o));
    return l > 0.0 ? scale3(o, 1.0 / l) : D3{0.0, 0.0, 0.0};
  }

  D3 a_, b_, c_;
  double solidAngle_ = 0.0, alpha_ = 0.0;
};

}  // namespace lvox
