#include "volume/media/dense_grid.h"

#include <cmath>

#include "src/core/error.h"
#include "src/core/names.h"

namespace lvox {

namespace {
constexpr Named<Interpolation> kInterpolationNames[] = {{Interpolation::Nearest, "nearest"},
                                                        {Interpolation::Trilinear, "trilinear"},
                                                        {Interpolation::Tricubic, "tricubic"}};
}  // namespace

Interpolation parseInterpolation(std::string_view name, const std::string& file,
                                 const std::string& field) {
  return parseNamed(name, kInterpolationNames, "interpolation", file, field);
}

std::string_view interpolationName(Interpolation i) { return nameOf(i, kInterpolationNames); }

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

std::vector<Bounds3> DenseGrid::occupiedWorldBoxes() const {
  std::vector<Bounds3> boxes;
  const Vec3 o(static_cast<float>(origin.x), static_cast<float>(origin.y),
               static_cast<float>(origin.z));
  const float k = static_cast<float>(kBlock);
  const Bounds3 padded = arrayBounds();
  for (int z = 0; z < bz; ++z)
    for (int y = 0; y < by; ++y)
      for (int x = 0; x < bx; ++x) {
        if (!blockOccupied[(static_cast<size_t>(z) * by + y) * bx + x]) continue;
        // The block's voxels and their half-voxel extent, clipped to the padded data box.
        const int block[3] = {x, y, z};
        Vec3 lo, hi;
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::max(static_cast<float>(block[a]) * k - 0.5f, padded.lo[a]);
          hi[a] = std::min(static_cast<float>(block[a] + 1) * k - 0.5f, padded.hi[a]);
        }
        Bounds3 world;
        for (int c = 0; c < 8; ++c)
          world.extend(indexToWorld.point(
              Vec3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z) + o));
        boxes.push_back(world);
      }
  return boxes;
}

void DenseGrid::intervals(const Ray& ray, float tmin, float tmax,
                          std::vector<std::pair<float, float>>& out) const {
  forEachBlock(ray, tmin, tmax, [&](float t0, float t1, size_t block) {
    if (!blockOccupied[block]) return;
    if (!out.empty() && out.back().second >= t0 - 1e-6f)
      out.back().second = t1;
    else
      out.emplace_back(t0, t1);
  });
}

void DenseGrid::computeBlockMax() {
  std::vector<float> own(static_cast<size_t>(bx) * by * bz, 0.0f);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        float& m = own[(static_cast<size_t>(z / kBlock) * by + y / kBlock) * bx + x / kBlock];
        m = std::max(m, voxel(x, y, z));
      }
  blockMax.assign(own.size(), 0.0f);
  for (int z = 0; z < bz; ++z)
    for (int y = 0; y < by; ++y)
      for (int x = 0; x < bx; ++x) {
        float m = 0.0f;
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int X = x + dx, Y = y + dy, Z = z + dz;
              if (X >= 0 && Y >= 0 && Z >= 0 && X < bx && Y < by && Z < bz)
                m = std::max(m, own[(static_cast<size_t>(Z) * by + Y) * bx + X]);
            }
        blockMax[(static_cast<size_t>(z) * by + y) * bx + x] = m;
      }
}

}  // namespace lvox
