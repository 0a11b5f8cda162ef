#pragma once
// Ray tests against single point-cloud elements and cluster proxies.
#include <algorithm>

#include "src/core/math.h"

namespace lvox {

// A straight cut through a disk, in its plane: the points q with dot(q - c, normal) >
// offset are not part of it. The zero normal (the default) cuts nothing.
struct DiskClip {
  Vec3 normal{0, 0, 0};
  float offset = 0.0f;
};

// Ray against a disk (centre c, unit normal n, radius r, cut by `clip`); t in
// (tmin, tmax). `front` is true when the ray arrives on the side n points to.
inline bool intersectDisk(const Ray& ray, const Vec3& c, const Vec3& n, float r,
                          const DiskClip& clip, float& t, bool& front) {
  const float denom = dot(n, ray.dir);
  if (std::abs(denom) < 1e-12f) return false;
  t = dot(c - ray.origin, n) / denom;
  if (!(t > ray.tmin && t < ray.tmax)) return false;
  const Vec3 d = ray.at(t) - c;
  if (dot(d, d) > r * r || dot(d, clip.normal) > clip.offset) return false;
  front = denom < 0.0f;
  return true;
}

// Chord [t0, t1] of the ray inside the cube centre +- h, clipped to [tmin, tmax]. A ray
// parallel to a face and lying exactly in it belongs to the cube on the + side only
// (half-open), so rays along grid planes are not counted in two neighbouring lvoxels.
inline bool intersectCube(const Ray& ray, const Vec3& c, float h, float& t0, float& t1) {
  t0 = ray.tmin;
  t1 = ray.tmax;
  for (int a = 0; a < 3; ++a) {
    const float lo = c[a] - h, hi = c[a] + h;
    if (ray.dir[a] == 0.0f) {
      if (ray.origin[a] < lo || ray.origin[a] >= hi) return false;
      continue;
    }
    const float inv = 1.0f / ray.dir[a];
    float tn = (lo - ray.origin[a]) * inv, tf = (hi - ray.origin[a]) * inv;
    if (tn > tf) std::swap(tn, tf);
    t0 = std::max(t0, tn);
    t1 = std::min(t1, tf);
  }
  return t1 > t0;
}

}  // namespace lvox
