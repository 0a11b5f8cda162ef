#include "src/render/lvoxel_field.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "src/core/error.h"

namespace lvox {

LvoxelField::LvoxelField(const Bounds3& bounds, float spacing, size_t channels)
    : origin_(bounds.lo), spacing_(spacing), channels_(channels) {
  double total = 1.0;
  for (int a = 0; a < 3; ++a) {
    cells_[a] = std::max(1L, static_cast<long>(std::ceil((bounds.hi[a] - bounds.lo[a]) / spacing)));
    total *= static_cast<double>(cells_[a]);
  }
  // The same guard as the lvoxel sampler's maxLvoxels: a spacing far too small for the
  // media is an input error, not an allocation failure.
  if (total > 5e7)
    throw InputError("pointcloud settings", "lvoxel_spacing",
                     "too small for the media: more than 50,000,000 cells");
  slot_.assign(static_cast<size_t>(total), -1);
}

long LvoxelField::cellOf(const Vec3& p) const {
  long c[3];
  for (int a = 0; a < 3; ++a) {
    c[a] = static_cast<long>(std::floor((p[a] - origin_[a]) / spacing_));
    if (c[a] < 0 || c[a] >= cells_[a]) return -1;
  }
  return index(c[0], c[1], c[2]);
}

uint32_t LvoxelField::occupy(const Vec3& p) {
  const long cell = cellOf(p);
  if (cell < 0) throw std::logic_error("lvoxel outside its own grid");
  int32_t& s = slot_[static_cast<size_t>(cell)];
  if (s < 0) {
    s = static_cast<int32_t>(centres_.size());
    long k = cell / (cells_[0] * cells_[1]);
    long j = (cell / cells_[0]) % cells_[1];
    long i = cell % cells_[0];
    centres_.push_back(origin_ + Vec3(static_cast<float>(i) + 0.5f, static_cast<float>(j) + 0.5f,
                                      static_cast<float>(k) + 0.5f) *
                                     spacing_);
    values_.resize(centres_.size() * channels_, RGB(0.0f));
  }
  return static_cast<uint32_t>(s);
}

long LvoxelField::slotOf(const Vec3& p) const {
  const long cell = cellOf(p);
  return cell < 0 ? -1 : slot_[static_cast<size_t>(cell)];
}

bool LvoxelField::interpolate(const Vec3& p, RGB* out) const {
  std::fill(out, out + channels_, RGB(0.0f));
  long base[3];
  float frac[3];
  for (int a = 0; a < 3; ++a) {
    const float u = (p[a] - origin_[a]) / spacing_ - 0.5f;  // cell-centre coordinates
    const float f = std::floor(u);
    base[a] = static_cast<long>(f);
    frac[a] = u - f;
  }
  float weightSum = 0.0f;
  for (int corner = 0; corner < 8; ++corner) {
    long c[3];
    float w = 1.0f;
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      const int bit = (corner >> a) & 1;
      c[a] = base[a] + bit;
      w *= bit ? frac[a] : 1.0f - frac[a];
      inside = inside && c[a] >= 0 && c[a] < cells_[a];
    }
    if (!inside || w <= 0.0f) continue;
    const int32_t s = slot_[static_cast<size_t>(index(c[0], c[1], c[2]))];
    if (s < 0) continue;
    const RGB* v = &values_[static_cast<size_t>(s) * channels_];
    for (size_t ch = 0; ch < channels_; ++ch) out[ch] += v[ch] * w;
    weightSum += w;
  }
  if (!(weightSum > 0.0f)) return false;
  const float inv = 1.0f / weightSum;
  for (size_t ch = 0; ch < channels_; ++ch) out[ch] *= inv;
  return true;
}

}  // namespace lvox
