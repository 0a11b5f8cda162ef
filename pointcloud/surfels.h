#pragma once
// Surfels: small two-sided Lambertian disks sampled on the scene's surfaces, stored as a
// struct of arrays so the octree and the gathers touch only the fields they need.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pointcloud/ray_element.h"
#include "src/core/math.h"

namespace lvox {

struct SurfelSet {
  std::vector<Vec3> position;
  std::vector<Vec3> normal;  // unit; "front" is the side it points to
  std::vector<float> radius;
  std::vector<RGB> albedo;
  std::vector<uint32_t> triangle;  // source triangle of the scene mesh (for materials)
  // The disk ends at the border of its surface: a disk near a convex edge would otherwise
  // stick out past it and show its other side (the inside of a solid) to gathers from the
  // adjoining face. A PointCloud keeps the cuts that cut in its traversal layout
  // (PointCloud::diskClip) and empties this array.
  std::vector<DiskClip> clip;
  // Sides that face the inside of a solid (bit 0: front, bit 1: back; see
  // buried_surfels.h). No ray from open space reaches them, so a gather ray that does
  // has met a disk sticking out of its surface (a convex curve, a corner) and passes by.
  std::vector<uint8_t> enclosedSides;
  // Cached outgoing radiance, W/(m^2 sr), of each side: L = albedo * E_direct / pi
  // (+ emission), filled by cacheDirectLight. Surfaces are two-sided in lvox, so a wall
  // lit from one side must stay dark seen from the other.
  std::vector<RGB> radianceFront;
  std::vector<RGB> radianceBack;
  // Disks are enlarged so that they cover the surface without holes; the surface area a
  // surfel stands for is pi r^2 / radiusScale^2 (used by the cluster aggregates).
  float radiusScale = 1.0f;

  size_t size() const { return position.size(); }
  float representedArea(size_t i) const {
    return kPi * radius[i] * radius[i] / (radiusScale * radiusScale);
  }
  void resize(size_t n) {
    position.resize(n);
    normal.resize(n);
    radius.resize(n);
    albedo.resize(n);
    triangle.resize(n);
    clip.resize(n);
    enclosedSides.assign(n, 0);
    radianceFront.assign(n, RGB(0.0f));
    radianceBack.assign(n, RGB(0.0f));
  }
  static constexpr size_t bytesPerElement() {
    return 2 * sizeof(Vec3) + sizeof(float) + 3 * sizeof(RGB) + sizeof(uint32_t) +
           sizeof(DiskClip) + sizeof(uint8_t);
  }
  size_t memoryBytes() const {
    return size() * (bytesPerElement() - sizeof(DiskClip)) + clip.size() * sizeof(DiskClip);
  }
  // Reorders every array so that new index i holds old element order[i]; an order that
  // lists only some elements keeps only those.
  void permute(const std::vector<uint32_t>& order);
};

// The surfels of a built cloud (PointCloud::surfels()). Each one's geometry is held once,
// in the record the traversal tests (DiskElement: position, radius, normal, the enclosed
// sides and its cut's index, 32 bytes), and read from there by everything else; beside it
// what the surfel carries: 68 bytes in all. (Issue 13: a second copy of the geometry cost
// 28 bytes per surfel.)
class CloudSurfels {
 public:
  CloudSurfels() = default;
  // Takes the sampled set, in its final order. The cuts that cut go to `clips`, and each
  // cut disk's record holds its index there.
  CloudSurfels(SurfelSet sampled, std::vector<DiskClip>& clips);

  size_t size() const { return albedo.size(); }
  const Vec3& position(size_t i) const { return disks_[i].position; }
  const Vec3& normal(size_t i) const { return disks_[i].normal; }
  float radius(size_t i) const { return disks_[i].radius; }
  uint8_t enclosedSides(size_t i) const { return static_cast<uint8_t>(disks_[i].flags & 3u); }
  float representedArea(size_t i) const {
    return kPi * radius(i) * radius(i) / (radiusScale * radiusScale);
  }
  // The records, with three empty ones past the end: 4-wide tests may read up to three
  // disks past a leaf.
  const std::vector<DiskElement>& disks() const { return disks_; }
  static constexpr size_t bytesPerElement() { return sizeof(DiskElement) + 3 * sizeof(RGB); }
  size_t memoryBytes() const;

  // As in SurfelSet; the light caches write the radiance. (The source triangle is not
  // kept: the sampler read the material through it, nothing after the build does.)
  std::vector<RGB> albedo;
  std::vector<RGB> radianceFront;
  std::vector<RGB> radianceBack;
  float radiusScale = 1.0f;

 private:
  std::vector<DiskElement> disks_;
};

}  // namespace lvox
