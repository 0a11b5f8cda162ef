#pragma once
// A scalar voxel grid copied out of an OpenVDB tree into a dense array over the active
// bounding box, plus a mask of occupied 8^3 blocks taken from the tree's active leaves
// and tiles (for empty-space skipping). Lookups are plain array reads: thread-safe, no
// OpenVDB in the hot path, and the same code for nearest, trilinear and tricubic.
#include <cstdint>
#include <string>
#include <vector>

#include "src/core/math.h"

namespace lvox {

enum class Interpolation { Nearest, Trilinear, Tricubic };

Interpolation parseInterpolation(const std::string& name, const std::string& file,
                                 const std::string& field);

struct DenseGrid {
  // Voxel (i, j, k) of the array has its centre at index coordinate origin + (i, j, k);
  // index -> world is `indexToWorld` (column vectors), voxel centres at integers as in
  // OpenVDB.
  int nx = 0, ny = 0, nz = 0;
  Imath::V3i origin{0, 0, 0};
  std::vector<float> values;
  Transform indexToWorld;
  Transform worldToIndex;
  float maxValue = 0.0f;
  // Occupied 8^3 blocks (dilated by one block so interpolation stencils are covered).
  static constexpr int kBlock = 8;
  int bx = 0, by = 0, bz = 0;
  std::vector<uint8_t> blockOccupied;

  bool empty() const { return values.empty(); }
  float voxel(int i, int j, int k) const {
    if (i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz) return 0.0f;
    return values[(static_cast<size_t>(k) * ny + j) * nx + i];
  }
  // Value at an index-space position (relative to `origin`).
  float sample(const Vec3& indexPos, Interpolation interp) const;
  // Index-space bounding box of the data, in array coordinates, padded by 2 voxels.
  Bounds3 arrayBounds() const;
  // World-space bounds of the data (the 8 transformed corners).
  Bounds3 worldBounds() const;
  // Sorted, merged t-intervals of `ray` (world space) over occupied blocks in [tmin, tmax].
  void intervals(const Ray& ray, float tmin, float tmax,
                 std::vector<std::pair<float, float>>& out) const;
  size_t memoryBytes() const { return values.size() * sizeof(float) + blockOccupied.size(); }
};

struct GridLoadReport {
  uint64_t clampedNegative = 0;
  float mostNegative = 0.0f;
  uint64_t activeVoxels = 0;
};

// Loads the float grid `gridName` of `file` (errors name `field`, e.g. "media[0].grid"),
// composing its own index->world map with `sceneTransform`. Errors: missing or corrupt
// file, missing grid (lists the grids), non-float or level-set grid, non-linear map,
// NaN/Inf values, a dense copy larger than 2^29 voxels.
DenseGrid loadVdbGrid(const std::string& file, const std::string& gridName,
                      const Transform& sceneTransform, const std::string& field,
                      GridLoadReport& report);

}  // namespace lvox
