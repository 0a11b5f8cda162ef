#pragma once
// The light cached on the lvoxel grid, as a field that camera rays read between lvoxel
// centres (pcb mode). All media share one grid, so overlapping media share their cells:
// the cached quantities (transmittance to each light, incident light) depend on the
// position only, not on the medium.
//
// Per occupied cell the field stores `channels` RGB values. Reading at a point blends the
// 8 surrounding cell centres trilinearly, over the occupied ones only (weights
// renormalised), so the field does not fade towards zero at the edge of the medium.
#include <cstdint>
#include <vector>

#include "src/core/math.h"

namespace lvox {

class LvoxelField {
 public:
  LvoxelField() = default;
  // A grid of cubes of side `spacing` from bounds.lo covering `bounds` (the lvoxel grid of
  // pointcloud/lvoxel_sampler.h), with `channels` RGB values per occupied cell.
  LvoxelField(const Bounds3& bounds, float spacing, size_t channels);

  float spacing() const { return spacing_; }
  size_t channels() const { return channels_; }
  size_t cellCount() const { return slot_.size(); }
  size_t occupiedCount() const { return centres_.size(); }
  // Index of the cell containing p, or -1 outside the grid.
  long cellOf(const Vec3& p) const;
  // Marks the cell containing p occupied (idempotent); returns its slot.
  uint32_t occupy(const Vec3& p);
  // Slot of the cell containing p, or -1 when it is not occupied.
  long slotOf(const Vec3& p) const;
  const Vec3& centre(uint32_t slot) const { return centres_[slot]; }
  RGB* values(uint32_t slot) { return &values_[slot * channels_]; }
  const RGB* values(uint32_t slot) const { return &values_[slot * channels_]; }

  // Writes the blended values at p into out[0 .. channels); false (and zeros) when no
  // occupied cell centre is within one cell of p.
  bool interpolate(const Vec3& p, RGB* out) const;

  size_t memoryBytes() const {
    return slot_.size() * sizeof(int32_t) + centres_.size() * sizeof(Vec3) +
           values_.size() * sizeof(RGB);
  }

 private:
  long index(long i, long j, long k) const { return (k * cells_[1] + j) * cells_[0] + i; }

  Vec3 origin_{0.0f, 0.0f, 0.0f};
  float spacing_ = 1.0f;
  long cells_[3] = {0, 0, 0};
  size_t channels_ = 0;
  std::vector<int32_t> slot_;  // per cell: index into centres_/values_, -1 if empty
  std::vector<Vec3> centres_;
  std::vector<RGB> values_;
};

}  // namespace lvox
