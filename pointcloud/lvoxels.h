#pragma once
// Lvoxels (Gibson 2011): small cells of participating medium with averaged coefficients
// and cached in-scattered light. An lvoxel is the axis-aligned cube of side 2*halfSize
// around its position: cubes of one grid tile space, so the optical depth summed over
// the lvoxels a ray crosses equals the optical depth of the averaged medium (see
// docs/pointcloud.md, "slab transmittance").
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pointcloud/lvoxel_light.h"
#include "src/core/math.h"

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
  // n lvoxels filled by hand (tests, benchmarks): each gets a light cell of its own, on a
  // grid that is only an index (n x 1 x 1 unit cells), not their positions.
  void resize(size_t n);
  // Radiance the lvoxel sends along any ray (isotropic source): (sigma_s L_s + its emission
  // source) / sigma_t. The emission is what lights the scene from an emissive medium.
  RGB sourceRadiance(size_t i) const;
  // Appends `other`'s lvoxels; their cells join this set's light (same grid required, or
  // this set empty). Light already cached in `other` is not carried over.
  void append(const LvoxelSet& other);
  static constexpr size_t bytesPerElement() {
    return sizeof(Vec3) + sizeof(float) + 2 * sizeof(RGB) + sizeof(uint32_t);
  }
  size_t memoryBytes() const { return size() * bytesPerElement() + emission.size() * sizeof(RGB); }
  void permute(const std::vector<uint32_t>& order);
};

}  // namespace lvox
