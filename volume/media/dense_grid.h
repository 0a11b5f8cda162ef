#pragma once
// A scalar voxel grid copied out of an OpenVDB tree into a dense array over the active
// bounding box, plus a mask of occupied 8^3 blocks taken from the tree's active leaves
// and tiles (for empty-space skipping). Lookups are plain array reads: thread-safe, no
// OpenVDB in the hot path, and the same code for nearest, trilinear and tricubic.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "src/core/math.h"

namespace lvox {

enum class Interpolation { Nearest, Trilinear, Tricubic };

// "nearest" | "trilinear" | "tricubic"; throws InputError(file, field, ...) otherwise.
Interpolation parseInterpolation(std::string_view name, const std::string& file,
                                 const std::string& field);
std::string_view interpolationName(Interpolation i);

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
  // Largest value that interpolation can return anywhere in each block (the maximum
  // over the block and its neighbours): a majorant grid for delta and ratio tracking.
  std::vector<float> blockMax;

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
  // World-space boxes of the occupied blocks (where the grid can be non-zero).
  std::vector<Bounds3> occupiedWorldBoxes() const;
  // Sorted, merged t-intervals of `ray` (world space) over occupied blocks in [tmin, tmax].
  void intervals(const Ray& ray, float tmin, float tmax,
                 std::vector<std::pair<float, float>>& out) const;
  // Calls f(t0, t1, blockMax) for each block the ray crosses in [tmin, tmax], in order.
  template <class F>
  void forEachBlock(const Ray& ray, float tmin, float tmax, F&& f) const;
  // Fills blockMax from values (after loading).
  void computeBlockMax();
  size_t memoryBytes() const {
    return values.size() * sizeof(float) + blockOccupied.size() + blockMax.size() * sizeof(float);
  }
};

template <class F>
void DenseGrid::forEachBlock(const Ray& ray, float tmin, float tmax, F&& f) const {
  if (empty()) return;
  // The same ray in array coordinates; t is preserved because the map is affine.
  const Vec3 o(static_cast<float>(origin.x), static_cast<float>(origin.y),
               static_cast<float>(origin.z));
  Ray local;
  local.origin = worldToIndex.point(ray.origin) - o;
  local.dir = worldToIndex.vector(ray.dir);
  local.tmin = tmin;
  local.tmax = tmax;
  float t0, t1;
  if (!arrayBounds().intersect(local, t0, t1)) return;
  // Amanatides-Woo DDA over 8^3 blocks; positions in the padding belong to edge blocks.
  const float k = static_cast<float>(kBlock);
  const Vec3 start = local.at(t0);
  int cell[3], step[3];
  const int dims[3] = {bx, by, bz};
  float tNext[3], tDelta[3];
  for (int a = 0; a < 3; ++a) {
    cell[a] = std::clamp(static_cast<int>(std::floor(start[a] / k)), 0, dims[a] - 1);
    const float d = local.dir[a];
    step[a] = d > 0.0f ? 1 : (d < 0.0f ? -1 : 0);
    tDelta[a] = step[a] != 0 ? k / std::abs(d) : kInf;
    const float boundary = static_cast<float>(cell[a] + (step[a] > 0 ? 1 : 0)) * k;
    tNext[a] = step[a] != 0 ? t0 + (boundary - start[a]) / d : kInf;
    // Edge blocks own the padding: their far boundary is the padded box.
    if ((step[a] > 0 && cell[a] == dims[a] - 1) || (step[a] < 0 && cell[a] == 0)) tNext[a] = kInf;
  }
  float t = t0;
  while (t < t1) {
    const int axis =
        tNext[0] < tNext[1] ? (tNext[0] < tNext[2] ? 0 : 2) : (tNext[1] < tNext[2] ? 1 : 2);
    const float exit = std::min(tNext[axis], t1);
    const size_t block = (static_cast<size_t>(cell[2]) * by + cell[1]) * bx + cell[0];
    if (exit > t) f(t, exit, block);
    t = exit;
    if (tNext[axis] == kInf) break;
    cell[axis] += step[axis];
    tNext[axis] += tDelta[axis];
    if ((step[axis] < 0 && cell[axis] == 0) || (step[axis] > 0 && cell[axis] == dims[axis] - 1))
      tNext[axis] = kInf;
  }
}

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
