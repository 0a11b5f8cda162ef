#include "pointcloud/lvoxel_light.h"

#include <algorithm>
#include <cmath>

#include "src/core/check.h"
#include "src/core/spherical_harmonics.h"

namespace lvox {

uint32_t LvoxelLight::occupy(long cell) {
  LVOX_CHECK(cell >= 0 && static_cast<double>(cell) < grid_.cellCount(),
             "lvoxel cell outside its own grid");
  if (slotOfCell_.empty()) slotOfCell_.assign(static_cast<size_t>(grid_.cellCount()), -1);
  int32_t& s = slotOfCell_[static_cast<size_t>(cell)];
  if (s < 0) {
    s = static_cast<int32_t>(cell_.size());
    cell_.push_back(cell);
    centre_.push_back(grid_.centre(cell));
    transmittance_.resize(cell_.size() * deltaLights_, RGB(0.0f));
    towardsCamera_.resize(cell_.size() * phases_, RGB(0.0f));
    area_.resize(cell_.size() * coefficientStride(), RGB(0.0f));
    direct_.resize(cell_.size() * coefficientStride(), RGB(0.0f));
    multi_.resize(cell_.size() * coefficientStride(), RGB(0.0f));
  }
  return static_cast<uint32_t>(s);
}

void LvoxelLight::setCoefficients(int count) {
  LVOX_CHECK(count == 1 || count == kShCoefficients, "lvoxel light: 1 or kShCoefficients");
  coefficients_ = count;
  area_.assign(cell_.size() * coefficientStride(), RGB(0.0f));
  direct_.assign(cell_.size() * coefficientStride(), RGB(0.0f));
  multi_.assign(cell_.size() * coefficientStride(), RGB(0.0f));
}

long LvoxelLight::slotOf(const Vec3& p) const {
  const long cell = grid_.cellOf(p);
  return cell < 0 || slotOfCell_.empty() ? -1 : slotOfCell_[static_cast<size_t>(cell)];
}

void LvoxelLight::setChannels(size_t deltaLights, size_t phases) {
  deltaLights_ = deltaLights;
  phases_ = phases;
  transmittance_.assign(cell_.size() * deltaLights, RGB(0.0f));
  towardsCamera_.assign(cell_.size() * phases, RGB(0.0f));
}

bool LvoxelLight::interpolate(const Vec3& p, LvoxelLightSample& out) const {
  out.transmittance.assign(deltaLights_, RGB(0.0f));
  out.multiScatter.assign(coefficientStride(), RGB(0.0f));
  out.towardsCamera.assign(phases_, RGB(0.0f));
  if (slotOfCell_.empty()) return false;
  long base[3];
  float frac[3];
  for (int a = 0; a < 3; ++a) {
    const float u = (p[a] - grid_.origin[a]) / grid_.spacing - 0.5f;  // cell-centre coordinates
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
      inside = inside && c[a] >= 0 && c[a] < grid_.cells[a];
    }
    if (!inside || w <= 0.0f) continue;
    const int32_t s = slotOfCell_[grid_.index(c[0], c[1], c[2])];
    if (s < 0) continue;
    const auto slot = static_cast<size_t>(s);
    const RGB* tr = transmittance_.data() + slot * deltaLights_;
    for (size_t k = 0; k < deltaLights_; ++k) out.transmittance[k] += tr[k] * w;
    const RGB* multi = multi_.data() + slot * coefficientStride();
    for (size_t k = 0; k < coefficientStride(); ++k) out.multiScatter[k] += multi[k] * w;
    const RGB* camera = towardsCamera_.data() + slot * phases_;
    for (size_t m = 0; m < phases_; ++m) out.towardsCamera[m] += camera[m] * w;
    weightSum += w;
  }
  if (!(weightSum > 0.0f)) return false;
  const float inv = 1.0f / weightSum;
  for (RGB& t : out.transmittance) t *= inv;
  for (RGB& c : out.multiScatter) c *= inv;
  for (RGB& c : out.towardsCamera) c *= inv;
  return true;
}

size_t LvoxelLight::memoryBytes() const {
  return slotOfCell_.size() * sizeof(int32_t) + cell_.size() * (sizeof(long) + sizeof(Vec3)) +
         (transmittance_.size() + towardsCamera_.size() + area_.size() + direct_.size() +
          multi_.size()) *
             sizeof(RGB);
}

}  // namespace lvox
