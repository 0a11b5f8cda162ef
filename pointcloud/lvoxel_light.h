#pragma once
// The light on lvoxels, its one home: per occupied cell of the lvoxel grid (shared by the
// media that overlap there, since the light depends on the position only):
//   - direct light, cached by the renderer in phase 1: for each of `deltaLights` point,
//     spot or directional lights the fraction of its light reaching the cell centre
//     (visibility x transmittance), so camera rays can apply the light's exact falloff,
//     spot profile and phase function; and, for each of `phases` phase functions, the
//     light of the area lights and the environment scattered towards the camera (the
//     only direction camera rays ever read: the direction from the cell centre to the
//     pinhole), which keeps anisotropic phases exact for that light;
//   - the phase-averaged direct in-scatter L_s (integral of phase * L_direct, for the
//     point cloud's isotropic cache);
//   - the multiple scattering gathered by the interreflection.
// The cloud reads inScatter (direct + multiple); camera rays read the blended channels.
#include <cstdint>
#include <vector>

#include "pointcloud/lvoxel_grid.h"
#include "src/core/check.h"
#include "src/core/collective.h"

namespace lvox {

// The light blended at a point between cell centres (LvoxelLight::interpolate).
struct LvoxelLightSample {
  std::vector<RGB> transmittance;  // one per delta light
  RGB multiScatter{0.0f};          // isotropic in-scatter of the interreflection
  std::vector<RGB> towardsCamera;  // area lights and environment, one per phase
};

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

  // Allocates the per-light transmittance and the per-phase light towards the camera
  // (zero) of every occupied cell.
  void setChannels(size_t deltaLights, size_t phases);
  size_t deltaLights() const { return deltaLights_; }
  size_t phases() const { return phases_; }
  // data() + offset, not &v[offset]: with no delta lights the array is empty.
  RGB* transmittance(uint32_t slot) {
    LVOX_DCHECK(slot < cell_.size(), "lvoxel light slot out of range");
    return transmittance_.data() + slot * deltaLights_;
  }
  const RGB* transmittance(uint32_t slot) const {
    LVOX_DCHECK(slot < cell_.size(), "lvoxel light slot out of range");
    return transmittance_.data() + slot * deltaLights_;
  }
  RGB* towardsCamera(uint32_t slot) { return towardsCamera_.data() + slot * phases_; }
  // The isotropic in-scatter of the area lights and the environment (their integral of
  // L dw over 4 pi), for the cloud's phase-averaged cache.
  RGB& areaInScatter(uint32_t slot) { return areaInScatter_[slot]; }
  RGB& directInScatter(uint32_t slot) { return directInScatter_[slot]; }
  RGB& multiScatter(uint32_t slot) { return multiScatter_[slot]; }
  const RGB& multiScatter(uint32_t slot) const { return multiScatter_[slot]; }
  // L_s for the point cloud: direct + multiple scattering.
  RGB inScatter(uint32_t slot) const { return directInScatter_[slot] + multiScatter_[slot]; }

  // Over several ranks that each filled the direct light (transmittance, towards the
  // camera, area in-scatter) of some cells and left the others zero: the sums over the
  // ranks give every rank every cell's light (adding zeros is exact). Collective.
  void sumDirectOverRanks(Collective& team) {
    team.sum(floatsOf(transmittance_));
    team.sum(floatsOf(towardsCamera_));
    team.sum(floatsOf(areaInScatter_));
  }

  // Camera rays: the light at p, blended trilinearly from the 8 surrounding cell centres
  // over the occupied ones only (weights renormalised, so the light does not fade towards
  // zero at the edge of the medium). False (and zeros) when no occupied centre is within
  // one cell of p.
  bool interpolate(const Vec3& p, LvoxelLightSample& out) const;

  size_t memoryBytes() const;

 private:
  LvoxelGrid grid_;
  size_t deltaLights_ = 0, phases_ = 0;
  std::vector<int32_t> slotOfCell_;  // per grid cell, allocated at the first occupy; -1 empty
  std::vector<long> cell_;           // per slot
  std::vector<Vec3> centre_;
  std::vector<RGB> transmittance_;  // slot-major, deltaLights_ per slot
  std::vector<RGB> towardsCamera_;  // slot-major, phases_ per slot
  std::vector<RGB> areaInScatter_, directInScatter_, multiScatter_;
};

}  // namespace lvox
