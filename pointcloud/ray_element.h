#pragma once
// Ray tests against single point-cloud elements and cluster proxies.
#include "src/core/math.h"

namespace lvox {

// Ray against a disk (centre c, unit normal n, radius r); t in (tmin, tmax).
// `front` is true when the ray arrives on the side n points to.
inline bool intersectDisk(const Ray& ray, const Vec3& c, const Vec3& n, float r, float& t,
                          bool& front) {
  const float denom = dot(n, ray.dir);
  if (std::abs(denom) < 1e-12f) return false;
  t = dot(c - ray.origin, n) / denom;
  if (!(t > ray.tmin && t < ray.tmax)) return false;
  const Vec3 d = ray.at(t) - c;
  if (dot(d, d) > r * r) return false;
  front = denom < 0.0f;
  return true;
}

// Chord [t0, t1] of the ray inside a sphere, clipped to [tmin, tmax].
inline bool intersectSphere(const Ray& ray, const Vec3& c, float r, float& t0, float& t1) {
  const Vec3 oc = c - ray.origin;
  const float tc = dot(oc, ray.dir);
  const float d2 = dot(oc, oc) - tc * tc;
  if (d2 >= r * r) return false;
  const float half = std::sqrt(r * r - d2);
  t0 = std::max(tc - half, ray.tmin);
  t1 = std::min(tc + half, ray.tmax);
  return t1 > t0;
}

}  // namespace lvox
