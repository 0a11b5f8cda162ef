#pragma once
// Lvoxels (Gibson 2011): small cells of participating medium with averaged coefficients
// and cached in-scattered light. An lvoxel is the axis-aligned cube of side 2*halfSize
// around its position: cubes of one grid tile space, so the optical depth summed over
// the lvoxels a ray crosses equals the optical depth of the averaged medium (see
// docs/pointcloud.md, "slab transmittance"). By default a cell the medium varies in gets
// the extinction that keeps the medium's mean transmittance across it rather than its
// mean extinction (lvoxel_sampler.h, transmittanceFactor).
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pointcloud/lvoxel_light.h"
#include "src/core/math.h"
#include "src/core/spherical_harmonics.h"

namespace lvox {

struct LvoxelSet {
  std::vector<Vec3> position;  // cube centre
  std::vector<float> halfSize;
  std::vector<RGB> sigmaA;  // 1/unit, averaged over the cube
  std::vector<RGB> sigmaS;
  std::vector<uint32_t> slot;  // the lvoxel's cell in `light`
  // The medium's emission source sigma_a * Le averaged over the cube (1/unit x radiance),
  // or empty when no medium the lvoxels were sampled from emits (then 0 for each).
  std::vector<RGB> emission;
  // Anisotropic media (empty when every lvoxel scatters isotropically): the Legendre
  // moments chi_1.. of the lvoxel's phase function with its forward peak removed
  // (delta-M: that peak is folded into sigma_s, which the renderer has reduced by it;
  // docs/pcb.md). They scale bands 1 and 2 of the light the lvoxel scatters.
  std::vector<std::array<float, kShBands - 1>> phaseMoments;
  // With ray-traced gathers: 1 where a surface cuts the lvoxel's cube (surfaceCutsCube,
  // own_cube.h), else 0; empty when not marked. Such an lvoxel's light is its centre's, on
  // one side of the surface, and a gather ray that crosses its cube on the other side does
  // not see it glow (docs/pcb.md, "Cubes that a surface cuts").
  std::vector<uint8_t> cut;
  // The light on the lvoxels' cells: in-scattered radiance L_s = integral of phase * L_i
  // over the sphere, W/(m^2 sr); the lvoxel's volume source is sigma_s * L_s.
  LvoxelLight light;

  size_t size() const { return position.size(); }
  RGB sigmaT(size_t i) const { return sigmaA[i] + sigmaS[i]; }
  float volume(size_t i) const {
    const float e = 2.0f * halfSize[i];
    return e * e * e;
  }
  RGB inScatter(size_t i) const { return light.inScatter(slot[i]); }
  // Coefficients of the light the lvoxel sends out (light.coefficients() of them,
  // spherical_harmonics.h): band l of its in-scatter times its phase's moment and
  // sigma_s / sigma_t, plus its emission source / sigma_t in the first. The radiance it
  // sends along a gather ray of direction wi (from the receiver to the lvoxel) is
  // sum c_k Yhat_k(wi).
  void sourceCoefficients(size_t i, RGB* out) const;
  // n lvoxels filled by hand (tests, benchmarks): each gets a light cell of its own, on a
  // grid that is only an index (n x 1 x 1 unit cells), not their positions.
  void resize(size_t n);
  // Radiance the lvoxel sends averaged over directions (all of it where it scatters
  // isotropically): (sigma_s L_s + its emission source) / sigma_t. The emission is what
  // lights the scene from an emissive medium.
  RGB sourceRadiance(size_t i) const;
  // The radiance it sends along a gather ray of direction wi, given Yhat(wi).
  RGB sourceRadiance(size_t i, const float* yhat) const;
  // Appends `other`'s lvoxels; their cells join this set's light (same grid required, or
  // this set empty). Light already cached in `other` is not carried over.
  void append(const LvoxelSet& other);
  static constexpr size_t bytesPerElement() {
    return sizeof(Vec3) + sizeof(float) + 2 * sizeof(RGB) + sizeof(uint32_t);
  }
  size_t memoryBytes() const {
    return size() * bytesPerElement() + emission.size() * sizeof(RGB) +
           phaseMoments.size() * sizeof(phaseMoments[0]) + cut.size() * sizeof(cut[0]);
  }
  void permute(const std::vector<uint32_t>& order);
};

}  // namespace lvox
