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
      : a_(unit(a, p)), b_(unit(b, p)), c_(unit(c, p)) {
    // Van Oosterom & Strackee: tan(solid angle / 2) = |a . (b x c)| / (1 + a.b + b.c + c.a).
    const double det = std::abs(a_.dot(b_.cross(c_)));
    const double denom = 1.0 + a_.dot(b_) + b_.dot(c_) + c_.dot(a_);
    solidAngle_ = 2.0 * std::atan2(det, denom);
    // The angle at vertex a between the great circles to b and to c.
    const Vec3d nab = a_.cross(b_), nac = a_.cross(c_);
    const double lab = nab.length(), lac = nac.length();
    alpha_ =
        lab > 0.0 && lac > 0.0 ? std::acos(std::clamp(nab.dot(nac) / (lab * lac), -1.0, 1.0)) : 0.0;
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
    const double v = s + sinAlpha * a_.dot(b_);
    const double q =
        std::clamp(((v * t - u * s) * cosAlpha - v) / ((v * s + u * t) * sinAlpha), -1.0, 1.0);
    const Vec3d cp = a_ * q + orthogonal(c_, a_) * std::sqrt(1.0 - q * q);
    // ... then the direction lies on the arc b-c', at cos z from b.
    const double z = 1.0 - u2 * (1.0 - cp.dot(b_));
    const Vec3d w = b_ * z + orthogonal(cp, b_) * std::sqrt(std::max(0.0, 1.0 - z * z));
    return Vec3(static_cast<float>(w.x), static_cast<float>(w.y), static_cast<float>(w.z));
  }

 private:
  // The unit vector from p to v (0 if they coincide).
  static Vec3d unit(const Vec3& v, const Vec3& p) {
    const Vec3 f = v - p;
    const Vec3d d(f.x, f.y, f.z);
    const double l = d.length();
    return l > 0.0 ? d / l : Vec3d(0.0);
  }
  // The unit vector along the part of v orthogonal to the unit vector n (0 if none).
  static Vec3d orthogonal(const Vec3d& v, const Vec3d& n) {
    const Vec3d o = v - n * v.dot(n);
    const double l = o.length();
    return l > 0.0 ? o / l : Vec3d(0.0);
  }

  Vec3d a_, b_, c_;
  double solidAngle_ = 0.0, alpha_ = 0.0;
};

}  // namespace lvox
