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
//   - the direct light as the point cloud sees it, and the multiple scattering gathered
//     by the interreflection: the incident radiance's spherical-harmonic coefficients
//     (spherical_harmonics.h: the first is its mean, the isotropic in-scatter L_s), one
//     per colour where every medium scatters isotropically, nine where one does not, so
//     that anisotropic lvoxels scatter it with their own phase (docs/pcb.md).
// The cloud reads inScatter (direct + multiple); camera rays read the blended channels.
//
// Camera channels (the delta lights' transmittance, the light towards the camera) are
// also kept without the media's attenuation ("clear": visibility alone, or the light that
// would arrive through empty space) and as the optical depth between the two, so that
// between cell centres the shadowing of geometry blends linearly and the media's
// attenuation exponentially (LvoxelLightBlend, docs/pcb.md "Blending the cells' light").
#include <cstdint>
#include <vector>

#include "pointcloud/lvoxel_grid.h"
#include "src/core/check.h"
#include "src/core/collective.h"
#include "src/geometry/ray_tracer.h"

namespace lvox {

// How camera rays blend the camera channels between the 8 nearest cell centres.
//   kLinear: trilinearly, the channels themselves (before stop 40).
//   kExponential: the clear light trilinearly, and the optical depth trilinearly over the
//     corners the clear light reaches; the channel is their clear x exp(-depth). An
//     optical depth is a line integral, as smooth in its starting point as the medium is,
//     so it blends linearly where its exponential does not: through a thick medium the
//     light falls exponentially across a cell, which a linear blend of the transmittance
//     overestimates (by 1.54x on average over a cell of optical depth 2.7). Geometry's
//     shadows stay in the clear part and blend linearly, as before.
enum class LvoxelLightBlend { kLinear, kExponential };

// The light blended at a point between cell centres (LvoxelLight::interpolate).
struct LvoxelLightSample {
  std::vector<RGB> transmittance;  // one per delta light
  std::vector<RGB> visibility;     // its part without the media (the clear light's blend)
  std::vector<RGB> multiScatter;   // the interreflection's coefficients (coefficients())
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
  // (zero) of every occupied cell, with their clear counterparts.
  void setChannels(size_t deltaLights, size_t phases);
  void setBlend(LvoxelLightBlend blend) { blend_ = blend; }
  LvoxelLightBlend blend() const { return blend_; }
  size_t deltaLights() const { return deltaLights_; }
  size_t phases() const { return phases_; }
  // Spherical-harmonic coefficients per colour of the cloud's light: 1 (isotropic) or 9.
  // Setting it zeroes the direct, area and multiple-scattering coefficients.
  void setCoefficients(int count);
  int coefficients() const { return coefficients_; }
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
  // The same channels without the media's attenuation: per delta light its visibility
  // (1 or 0 per colour), per phase the light towards the camera through empty space.
  // Written while the direct light is cached; released by finishCameraChannels.
  RGB* transmittanceClear(uint32_t slot) { return clear_.data() + slot * cameraStride(); }
  RGB* towardsCameraClear(uint32_t slot) {
    return clear_.data() + slot * cameraStride() + deltaLights_;
  }
  // Once the direct light is complete (after sumDirectOverRanks): each camera channel's
  // clear light and optical depth, -log(attenuated / clear), side by side for the
  // exponential blend. The clear channels above are released.
  void finishCameraChannels();
  // The incident light of the area lights and the environment as the cloud sees it
  // (coefficients() values; the first is its integral of L dw over 4 pi).
  RGB* areaInScatter(uint32_t slot) { return area_.data() + slot * coefficientStride(); }
  // The direct light's coefficients (delta lights and the area ones), and the multiple
  // scattering's (the interreflection's).
  RGB* directInScatter(uint32_t slot) { return direct_.data() + slot * coefficientStride(); }
  const RGB* directInScatter(uint32_t slot) const {
    return direct_.data() + slot * coefficientStride();
  }
  RGB* multiScatter(uint32_t slot) { return multi_.data() + slot * coefficientStride(); }
  const RGB* multiScatter(uint32_t slot) const {
    return multi_.data() + slot * coefficientStride();
  }
  // L_s's coefficient k for the point cloud: direct + multiple scattering.
  RGB inScatter(uint32_t slot, int k = 0) const {
    const size_t i = slot * coefficientStride() + static_cast<size_t>(k);
    return direct_[i] + multi_[i];
  }

  // Over several ranks that each filled the direct light (transmittance, towards the
  // camera, area in-scatter) of some cells and left the others zero: the sums over the
  // ranks give every rank every cell's light (adding zeros is exact). Collective.
  void sumDirectOverRanks(Collective& team) {
    team.sum(floatsOf(transmittance_));
    team.sum(floatsOf(towardsCamera_));
    team.sum(floatsOf(clear_));
    team.sum(floatsOf(area_));
  }

  // Camera rays: the light at p, blended from the 8 surrounding cell centres over the
  // occupied ones only (weights renormalised, so the light does not fade towards zero at
  // the edge of the medium), the camera channels as blend() says. False (and zeros) when
  // no occupied centre is within one cell of p.
  // With `tracer`, a corner marked near a surface (markNearSurface) whose centre a surface
  // hides from p is left out too: its light is from the other side of a wall.
  bool interpolate(const Vec3& p, LvoxelLightSample& out, const RayTracer* tracer = nullptr) const;
  // Marks a cell with a surface within one cell spacing of its centre (per axis): a point
  // its light blends into may lie across that surface.
  void markNearSurface(uint32_t slot) {
    nearSurface_.resize(cell_.size(), 0);
    nearSurface_[slot] = 1;
  }

  size_t memoryBytes() const;

 private:
  LvoxelGrid grid_;
  size_t deltaLights_ = 0, phases_ = 0;
  std::vector<int32_t> slotOfCell_;  // per grid cell, allocated at the first occupy; -1 empty
  std::vector<long> cell_;           // per slot
  std::vector<Vec3> centre_;
  std::vector<RGB> transmittance_;  // slot-major, deltaLights_ per slot
  std::vector<RGB> towardsCamera_;  // slot-major, phases_ per slot
  // Slot-major, cameraStride() per slot: the delta lights' channels, then the phases'.
  std::vector<RGB> clear_;  // while the direct light is cached
  struct Blendable {
    RGB clear, depth;
  };
  // From finishCameraChannels on; its size tells whether that has run since the cells or
  // channels last changed.
  std::vector<Blendable> blendable_;
  LvoxelLightBlend blend_ = LvoxelLightBlend::kExponential;
  size_t cameraStride() const { return deltaLights_ + phases_; }
  // Camera channel k of a slot with the media: a delta light's transmittance, then the
  // phases' light towards the camera.
  const RGB& attenuatedChannel(size_t slot, size_t k) const {
    return k < deltaLights_ ? transmittance_[slot * deltaLights_ + k]
                            : towardsCamera_[slot * phases_ + (k - deltaLights_)];
  }
  // The camera channels at the occupied corners (slots, weights summing to weightSum).
  void blendCameraChannels(const size_t* slots, const float* weights, int corners, float weightSum,
                           LvoxelLightSample& out) const;
  // Delta light k's visibility (its clear channel) blended over the corners (1 / their
  // weights' sum: inv), for the linear blend (the exponential one blends it anyway).
  RGB blendedVisibility(const size_t* slots, const float* weights, int corners, float inv,
                        size_t k) const;
  int coefficients_ = 1;
  size_t coefficientStride() const { return static_cast<size_t>(coefficients_); }
  std::vector<RGB> area_, direct_, multi_;  // slot-major, coefficients_ per slot
  std::vector<uint8_t> nearSurface_;        // per slot (empty: none marked)
};

}  // namespace lvox
