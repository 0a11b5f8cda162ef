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
    clear_.resize(cell_.size() * cameraStride(), RGB(0.0f));
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
  clear_.assign(cell_.size() * cameraStride(), RGB(0.0f));
  blendable_.clear();
}

void LvoxelLight::finishCameraChannels() {
  // Deeper than this the light is e^-80 of its clear value: nothing a float shows.
  constexpr float kMaxDepth = 80.0f;
  const size_t stride = cameraStride();
  LVOX_CHECK(clear_.size() == cell_.size() * stride, "lvoxel light: no clear channels");
  blendable_.resize(clear_.size());
  for (size_t slot = 0; slot < cell_.size(); ++slot)
    for (size_t k = 0; k < stride; ++k) {
      const RGB& attenuated = attenuatedChannel(slot, k);
      Blendable& b = blendable_[slot * stride + k];
      b.clear = clear_[slot * stride + k];
      for (int c = 0; c < 3; ++c)
        b.depth[c] = b.clear[c] > 0.0f && attenuated[c] > 0.0f
                         ? std::clamp(-std::log(attenuated[c] / b.clear[c]), 0.0f, kMaxDepth)
                         : (b.clear[c] > 0.0f ? kMaxDepth : 0.0f);
      // Colours whose depths agree to rounding (grey media) share one, so that blending
      // them takes one exponential.
      const float mean = average(b.depth);
      if (std::abs(b.depth.x - mean) <= 1e-6f * mean &&
          std::abs(b.depth.y - mean) <= 1e-6f * mean && std::abs(b.depth.z - mean) <= 1e-6f * mean)
        b.depth = RGB(mean);
    }
  std::vector<RGB>().swap(clear_);
}

bool LvoxelLight::interpolate(const Vec3& p, LvoxelLightSample& out,
                              const RayTracer* tracer) const {
  out.transmittance.assign(deltaLights_, RGB(0.0f));
  out.visibility.assign(deltaLights_, RGB(0.0f));
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
  int corners = 0;
  size_t slots[8];
  float weights[8];
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
    if (tracer && !nearSurface_.empty() && nearSurface_[static_cast<size_t>(s)] &&
        tracer->blocked(p, centre_[static_cast<size_t>(s)]))
      continue;
    slots[corners] = static_cast<size_t>(s);
    weights[corners++] = w;
    weightSum += w;
  }
  if (!(weightSum > 0.0f)) return false;
  const float inv = 1.0f / weightSum;
  for (int i = 0; i < corners; ++i) {
    const RGB* multi = multi_.data() + slots[i] * coefficientStride();
    for (size_t k = 0; k < coefficientStride(); ++k) out.multiScatter[k] += multi[k] * weights[i];
  }
  for (RGB& c : out.multiScatter) c *= inv;
  blendCameraChannels(slots, weights, corners, weightSum, out);
  return true;
}

namespace {

// exp(-depth / weight) per colour (1 where the weight is zero): one exponential where the
// colours agree, as they do in grey media and white lights.
RGB attenuation(const RGB& depth, float weight) {
  if (!(weight > 0.0f)) return RGB(1.0f);
  auto one = [&](float d) { return d > 0.0f ? std::exp(-d / weight) : 1.0f; };
  if (depth.x == depth.y && depth.y == depth.z) return RGB(one(depth.x));
  return RGB(one(depth.x), one(depth.y), one(depth.z));
}

}  // namespace

namespace {

// Rounding must not make a light that every corner sees look partly hidden.
RGB wholeWhereEveryCornerSees(RGB visible) {
  for (int c = 0; c < 3; ++c)
    if (visible[c] >= 1.0f - 1e-5f) visible[c] = 1.0f;
  return visible;
}

}  // namespace

RGB LvoxelLight::blendedVisibility(const size_t* slots, const float* weights, int corners,
                                   float inv, size_t k) const {
  // Without the clear channels (a light whose camera channels were set by hand) every
  // corner counts as seeing the light.
  if (blendable_.empty()) return RGB(1.0f);
  RGB clear(0.0f);
  for (int i = 0; i < corners; ++i)
    clear += blendable_[slots[i] * cameraStride() + k].clear * weights[i];
  return clear * inv;
}

void LvoxelLight::blendCameraChannels(const size_t* slots, const float* weights, int corners,
                                      float weightSum, LvoxelLightSample& out) const {
  const float inv = 1.0f / weightSum;
  auto linear = [&](size_t k) {
    RGB sum(0.0f);
    for (int i = 0; i < corners; ++i) sum += attenuatedChannel(slots[i], k) * weights[i];
    return sum * inv;
  };
  LVOX_CHECK(
      blend_ == LvoxelLightBlend::kLinear || blendable_.size() == cell_.size() * cameraStride(),
      "lvoxel light: exponential blend before finishCameraChannels");
  // Also gives the blended clear light (for a delta light: its visibility).
  auto exponential = [&](size_t k, RGB& blendedClear) {
    const size_t stride = cameraStride();
    RGB clear(0.0f), depth(0.0f);
    float depthWeight = 0.0f;
    for (int i = 0; i < corners; ++i) {
      const Blendable& b = blendable_[slots[i] * stride + k];
      clear += b.clear * weights[i];
      // A corner the light does not reach has no depth to give (its colours are all dark,
      // or the light has none of that colour).
      if (b.clear.x + b.clear.y + b.clear.z > 0.0f) {
        depth += b.depth * weights[i];
        depthWeight += weights[i];
      }
    }
    blendedClear = clear * inv;
    return blendedClear * attenuation(depth, depthWeight);
  };
  for (size_t k = 0; k < cameraStride(); ++k) {
    const bool linearBlend = blend_ == LvoxelLightBlend::kLinear;
    RGB clear(1.0f);
    const RGB value = linearBlend ? linear(k) : exponential(k, clear);
    if (k < deltaLights_) {
      out.transmittance[k] = value;
      if (linearBlend) clear = blendedVisibility(slots, weights, corners, inv, k);
      out.visibility[k] = wholeWhereEveryCornerSees(clear);
    } else {
      out.towardsCamera[k - deltaLights_] = value;
    }
  }
}

size_t LvoxelLight::memoryBytes() const {
  return slotOfCell_.size() * sizeof(int32_t) + cell_.size() * (sizeof(long) + sizeof(Vec3)) +
         (transmittance_.size() + towardsCamera_.size() + clear_.size() + area_.size() +
          direct_.size() + multi_.size()) *
             sizeof(RGB) +
         blendable_.size() * sizeof(Blendable) + nearSurface_.size();
}

}  // namespace lvox
