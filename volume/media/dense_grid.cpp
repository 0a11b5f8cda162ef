#include "volume/media/dense_grid.h"

#include <cmath>

#include "src/core/error.h"

namespace lvox {

Interpolation parseInterpolation(const std::string& name, const std::string& file,
                                 const std::string& field) {
  if (name == "nearest") return Interpolation::Nearest;
  if (name == "trilinear") return Interpolation::Trilinear;
  if (name == "tricubic") return Interpolation::Tricubic;
  throw InputError(file, field,
                   "unknown interpolation '" + name + "' (nearest, trilinear, tricubic)");
}

namespace {

// Uniform cubic B-spline weights for fractional position f in [0, 1) (taps -1..2).
void bsplineWeights(float f, float w[4]) {
  const float f2 = f * f, f3 = f2 * f;
  w[0] = (1.0f - 3.0f * f + 3.0f * f2 - f3) / 6.0f;
  w[1] = (4.0f - 6.0f * f2 + 3.0f * f3) / 6.0f;
  w[2] = (1.0f + 3.0f * f + 3.0f * f2 - 3.0f * f3) / 6.0f;
  w[3] = f3 / 6.0f;
}

}  // namespace

float DenseGrid::sample(const Vec3& p, Interpolation interp) const {
  switch (interp) {
    case Interpolation::Nearest:
      return voxel(static_cast<int>(std::floor(p.x + 0.5f)),
                   static_cast<int>(std::floor(p.y + 0.5f)),
                   static_cast<int>(std::floor(p.z + 0.5f)));
    case Interpolation::Trilinear: {
      const float fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
      const int i = static_cast<int>(fx), j = static_cast<int>(fy), k = static_cast<int>(fz);
      const float tx = p.x - fx, ty = p.y - fy, tz = p.z - fz;
      auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
      const float c00 = lerp(voxel(i, j, k), voxel(i + 1, j, k), tx);
      const float c10 = lerp(voxel(i, j + 1, k), voxel(i + 1, j + 1, k), tx);
      const float c01 = lerp(voxel(i, j, k + 1), voxel(i + 1, j, k + 1), tx);
      const float c11 = lerp(voxel(i, j + 1, k + 1), voxel(i + 1, j + 1, k + 1), tx);
      return lerp(lerp(c00, c10, ty), lerp(c01, c11, ty), tz);
    }
    case Interpolation::Tricubic: {
      // C2 cubic B-spline (approximating: it smooths the data slightly, which is the
      // point: solvers keep their order up to 4 on it).
      const float fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
      const int i = static_cast<int>(fx), j = static_cast<int>(fy), k = static_cast<int>(fz);
      float wx[4], wy[4], wz[4];
      bsplineWeights(p.x - fx, wx);
      bsplineWeights(p.y - fy, wy);
      bsplineWeights(p.z - fz, wz);
      float sum = 0.0f;
      for (int c = 0; c < 4; ++c) {
        float plane = 0.0f;
        for (int b = 0; b < 4; ++b) {
          float row = 0.0f;
          for (int a = 0; a < 4; ++a) row += wx[a] * voxel(i - 1 + a, j - 1 + b, k - 1 + c);
          plane += wy[b] * row;
        }
        sum += wz[c] * plane;
      }
      return std::max(0.0f, sum);
    }
  }
  return 0.0f;
}

Bounds3 DenseGrid::arrayBounds() const {
  Bounds3 b;
  b.lo = Vec3(-2.0f, -2.0f, -2.0f);
  b.hi = Vec3(static_cast<float>(nx) + 1.0f, static_cast<float>(ny) + 1.0f,
              static_cast<float>(nz) + 1.0f);
  return b;
}

Bounds3 DenseGrid::worldBounds() const {
  Bounds3 world;
  if (empty()) return world;
  const Bounds3 a = arrayBounds();
  const Vec3 o(static_cast<float>(origin.x), static_cast<float>(origin.y),
               static_cast<float>(origin.z));
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner(c & 1 ? a.hi.x : a.lo.x, c & 2 ? a.hi.y : a.lo.y, c & 4 ? a.hi.z : a.lo.z);
    world.extend(indexToWorld.point(corner + o));
  }
  return world;
}

void DenseGrid::intervals(const Ray& ray, float tmin, float tmax,
                          std::vector<std::pair<float, float>>& out) const {
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
  int cell[3], step[3], dims[3] = {bx, by, bz};
  float tNext[3], tDelta[3];
  for (int a = 0; a < 3; ++a) {
    cell[a] = std::clamp(static_cast<int>(std::floor(start[a] / k)), 0, dims[a] - 1);
    const float d = local.dir[a];
    if (d > 0.0f) {
      step[a] = 1;
      tNext[a] = t0 + ((static_cast<float>(cell[a] + 1) * k) - start[a]) / d;
      tDelta[a] = k / d;
    } else if (d < 0.0f) {
      step[a] = -1;
      tNext[a] = t0 + ((static_cast<float>(cell[a]) * k) - start[a]) / d;
      tDelta[a] = -k / d;
    } else {
      step[a] = 0;
      tNext[a] = kInf;
      tDelta[a] = kInf;
    }
    // Edge blocks own the padding: their far boundary is the padded box.
    if (step[a] > 0 && cell[a] == dims[a] - 1) tNext[a] = kInf;
    if (step[a] < 0 && cell[a] == 0) tNext[a] = kInf;
  }
  float t = t0;
  while (t < t1) {
    const int axis =
        tNext[0] < tNext[1] ? (tNext[0] < tNext[2] ? 0 : 2) : (tNext[1] < tNext[2] ? 1 : 2);
    const float exit = std::min(tNext[axis], t1);
    if (blockOccupied[(static_cast<size_t>(cell[2]) * by + cell[1]) * bx + cell[0]]) {
      if (!out.empty() && out.back().second >= t - 1e-6f)
        out.back().second = exit;
      else
        out.emplace_back(t, exit);
    }
    t = exit;
    if (tNext[axis] == kInf) break;
    cell[axis] += step[axis];
    tNext[axis] += tDelta[axis];
    if (cell[axis] == 0 && step[axis] < 0) tNext[axis] = kInf;
    if (cell[axis] == dims[axis] - 1 && step[axis] > 0) tNext[axis] = kInf;
  }
}

}  // namespace lvox
