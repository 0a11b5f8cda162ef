#pragma once
// The light on lvoxels, its one home: per occupied cell of the lvoxel grid (shared by the
// media that overlap there, since the light depends on the position only):
//   - direct light, cached by the renderer in phase 1: for each of `deltaLights` point,
//     spot or directional lights the fraction of its light reaching the cell centre
//     (visibility x transmittance), so camera rays can apply the light's exact falloff,
//     spot profile and phase function; and the isotropic in-scatter from area lights and
//     the environment;
//   - the phase-averaged direct in-scatter L_s (integral of phase * L_direct, for the
//     point cloud's isotropic cache);
//   - the multiple scattering gathered by the interreflection.
// The cloud reads inScatter (direct + multiple); camera rays read the blended channels.
#include <cstdint>
#include <vector>

#include "pointcloud/lvoxel_grid.h"

namespace lvox {

class LvoxelLight {
 public:
  LvoxelLight() = default;
  explicit LvoxelLight(const LvoxelGrid& grid) : grid_(grid) {}

  const LvoxelGrid& grid() const { return grid_; }
  size_t occupiedCount() const { return cell_.size(); }
  // Marks a grid cell occupied (idempotent); returns its slot.
  uint32_t occupy(long cell);
  // Slot of the cell containing p, or -1 when it is not occupied.
  long slotOf(const Vec3& p) const;
  long cellOfSlot(uint32_t slot) const { return cell_[slot]; }
  const Vec3& centre(uint32_t slot) const { return centre_[slot]; }

  // Allocates the per-light transmittance (zero) of every occupied cell.
  void setDeltaLights(size_t count);
  size_t deltaLights() const { return deltaLights_; }
  RGB* transmittance(uint32_t slot) { return &transmittance_[slot * deltaLights_]; }
  const RGB* transmittance(uint32_t slot) const { return &transmittance_[slot * deltaLights_]; }
  RGB& areaInScatter(uint32_t slot) { return areaInScatter_[slot]; }
  RGB& directInScatter(uint32_t slot) { return directInScatter_[slot]; }
  RGB& multiScatter(uint32_t slot) { return multiScatter_[slot]; }
  const RGB& multiScatter(uint32_t slot) const { return multiScatter_[slot]; }
  // L_s for the point cloud: direct + multiple scattering.
  RGB inScatter(uint32_t slot) const { return directInScatter_[slot] + multiScatter_[slot]; }

  // Camera rays: channels() values at p, blended trilinearly from the 8 surrounding cell
  // centres over the occupied ones only (weights renormalised, so the light does not fade
  // towards zero at the edge of the medium): the delta lights' transmittances, then the
  // isotropic in-scatter (area lights and environment plus multiple scattering). False
  // (and zeros) when no occupied centre is within one cell of p.
  size_t channels() const { return deltaLights_ + 1; }
  bool interpolate(const Vec3& p, RGB* out) const;

  size_t memoryBytes() const;

 private:
  LvoxelGrid grid_;
  size_t deltaLights_ = 0;
  std::vector<int32_t> slotOfCell_;  // per grid cell, allocated at the first occupy; -1 empty
  std::vector<long> cell_;           // per slot
  std::vector<Vec3> centre_;
  std::vector<RGB> transmittance_;  // slot-major, deltaLights_ per slot
  std::vector<RGB> areaInScatter_, directInScatter_, multiScatter_;
};

}  // namespace lvox
