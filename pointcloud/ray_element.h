#pragma once
// Ray tests against single point-cloud elements and cluster proxies.
#include <algorithm>
#include <cstdint>

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

// A surfel's disk as the traversal tests it: 32 bytes per surfel in octree order, so a
// leaf's disks are adjacent in memory. In a built cloud it is the surfel's only copy of
// its geometry (CloudSurfels). The cut is read from a side array, and only for disks that
// have one.
struct DiskElement {
  // flags: bits 0-1 are the enclosed sides, bit 2 says the disk is cut, and bits 3-31 are
  // then the index of its cut in PointCloud's list of them.
  static constexpr uint32_t kClipped = 4;
  static constexpr uint32_t kClipShift = 3;
  // Zeros by default: the padding records past the last leaf are loaded by 4-wide tests.
  Vec3 position = Vec3(0.0f);
  float radius = 0.0f;
  Vec3 normal = Vec3(0.0f);
  uint32_t flags = 0;

  // A cut with a zero normal and offset >= 0 never removes anything (dot(d, 0) > offset
  // is false for every d, NaN included), so testing it can be skipped.
  static bool cuts(const DiskClip& c) {
    return !(c.normal.x == 0.0f && c.normal.y == 0.0f && c.normal.z == 0.0f && c.offset >= 0.0f);
  }
};

// intersectDisk on the packed record: the same operations in the same order, so t and
// the verdict are bit-identical.
inline bool intersectDisk(const Ray& ray, const DiskElement& d, const DiskClip& clip, float& t,
                          bool& front) {
  const float denom = dot(d.normal, ray.dir);
  if (std::abs(denom) < 1e-12f) return false;
  t = dot(d.position - ray.origin, d.normal) / denom;
  if (!(t > ray.tmin && t < ray.tmax)) return false;
  const Vec3 p = ray.at(t) - d.position;
  if (dot(p, p) > d.radius * d.radius) return false;
  if ((d.flags & DiskElement::kClipped) && dot(p, clip.normal) > clip.offset) return false;
  front = denom < 0.0f;
  return true;
}

// Chord [t0, t1] of the ray inside the box [lo, hi], clipped to [tmin, tmax]. A ray
// parallel to a face and lying exactly in it belongs to the box on the + side only
// (half-open), so rays along grid planes are not counted in two neighbouring lvoxels.
// `inv` is 1 / ray.dir per axis (computed once per ray by callers that test many boxes).
inline bool intersectBox(const Ray& ray, const Vec3& inv, const Vec3& lo, const Vec3& hi, float& t0,
                         float& t1) {
  t0 = ray.tmin;
  t1 = ray.tmax;
  for (int a = 0; a < 3; ++a) {
    if (ray.dir[a] == 0.0f) {
      if (ray.origin[a] < lo[a] || ray.origin[a] >= hi[a]) return false;
      continue;
    }
    float tn = (lo[a] - ray.origin[a]) * inv[a], tf = (hi[a] - ray.origin[a]) * inv[a];
    if (tn > tf) std::swap(tn, tf);
    t0 = std::max(t0, tn);
    t1 = std::min(t1, tf);
  }
  return t1 > t0;
}

inline Vec3 inverseDirection(const Ray& ray) {
  return Vec3(1.0f / ray.dir.x, 1.0f / ray.dir.y, 1.0f / ray.dir.z);
}

inline bool intersectBox(const Ray& ray, const Vec3& lo, const Vec3& hi, float& t0, float& t1) {
  return intersectBox(ray, inverseDirection(ray), lo, hi, t0, t1);
}

// The same for the cube centre +- h.
inline bool intersectCube(const Ray& ray, const Vec3& inv, const Vec3& c, float h, float& t0,
                          float& t1) {
  return intersectBox(ray, inv, c - Vec3(h, h, h), c + Vec3(h, h, h), t0, t1);
}
inline bool intersectCube(const Ray& ray, const Vec3& c, float h, float& t0, float& t1) {
  return intersectCube(ray, inverseDirection(ray), c, h, t0, t1);
}

// An lvoxel's cube packed for the traversal (LvoxelSet keeps centre and size apart).
struct CubeElement {
  Vec3 centre;
  float halfSize = 0.0f;
};

}  // namespace lvox
