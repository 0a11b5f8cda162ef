#include <algorithm>

#include "pointcloud/lvoxels.h"
#include "pointcloud/surfels.h"
#include "src/core/check.h"
#include "src/core/spherical_harmonics.h"

namespace lvox {

namespace {

template <class T>
void permuteArray(std::vector<T>& v, const std::vector<uint32_t>& order) {
  std::vector<T> out(order.size());
  for (size_t i = 0; i < order.size(); ++i) out[i] = v[order[i]];
  v.swap(out);
}

float ratio(float num, float den) { return den > 0.0f ? num / den : 0.0f; }

}  // namespace

void SurfelSet::permute(const std::vector<uint32_t>& order) {
  permuteArray(position, order);
  permuteArray(normal, order);
  permuteArray(radius, order);
  permuteArray(albedo, order);
  permuteArray(triangle, order);
  permuteArray(clip, order);
  permuteArray(enclosedSides, order);
  permuteArray(radianceFront, order);
  permuteArray(radianceBack, order);
}

CloudSurfels::CloudSurfels(SurfelSet sampled, std::vector<DiskClip>& clips)
    : albedo(std::move(sampled.albedo)),
      radianceFront(std::move(sampled.radianceFront)),
      radianceBack(std::move(sampled.radianceBack)),
      radiusScale(sampled.radiusScale) {
  const size_t n = sampled.size();
  disks_.assign(n + (n > 0 ? 3 : 0), DiskElement{});
  clips.clear();
  for (size_t i = 0; i < n; ++i) {
    uint32_t clipped = 0;
    if (i < sampled.clip.size() && DiskElement::cuts(sampled.clip[i])) {
      LVOX_CHECK(clips.size() < (size_t(1) << (32 - DiskElement::kClipShift)),
                 "too many cut disks for the traversal layout");
      clipped =
          DiskElement::kClipped | static_cast<uint32_t>(clips.size() << DiskElement::kClipShift);
      clips.push_back(sampled.clip[i]);
    }
    disks_[i] = {sampled.position[i], sampled.radius[i], sampled.normal[i],
                 (sampled.enclosedSides[i] & 3u) | clipped};
  }
  clips.shrink_to_fit();
}

size_t CloudSurfels::memoryBytes() const {
  return disks_.capacity() * sizeof(DiskElement) + albedo.capacity() * sizeof(RGB) +
         radianceFront.capacity() * sizeof(RGB) + radianceBack.capacity() * sizeof(RGB);
}

RGB LvoxelSet::sourceRadiance(size_t i) const {
  const RGB st = sigmaT(i);
  const RGB ls = inScatter(i);
  const RGB scattered(ratio(sigmaS[i].x, st.x) * ls.x, ratio(sigmaS[i].y, st.y) * ls.y,
                      ratio(sigmaS[i].z, st.z) * ls.z);
  if (emission.empty()) return scattered;
  const RGB& e = emission[i];
  return scattered + RGB(ratio(e.x, st.x), ratio(e.y, st.y), ratio(e.z, st.z));
}

void LvoxelSet::sourceCoefficients(size_t i, RGB* out) const {
  out[0] = sourceRadiance(i);
  const int count = light.coefficients();
  if (count == 1) return;
  const RGB st = sigmaT(i);
  const RGB albedo(ratio(sigmaS[i].x, st.x), ratio(sigmaS[i].y, st.y), ratio(sigmaS[i].z, st.z));
  const std::array<float, kShBands - 1> chi =
      phaseMoments.empty() ? std::array<float, kShBands - 1>{} : phaseMoments[i];
  for (int k = 1; k < count; ++k)
    out[k] = albedo * light.inScatter(slot[i], k) * chi[static_cast<size_t>(shBand(k) - 1)];
}

RGB LvoxelSet::sourceRadiance(size_t i, const float* yhat) const {
  RGB c[kShCoefficients];
  sourceCoefficients(i, c);
  return shDot(c, yhat, light.coefficients());
}

void LvoxelSet::resize(size_t n) {
  position.resize(n);
  halfSize.resize(n);
  sigmaA.resize(n);
  sigmaS.resize(n);
  if (!emission.empty()) emission.resize(n, RGB(0.0f));
  if (!phaseMoments.empty()) phaseMoments.resize(n, {});
  light =
      LvoxelLight(LvoxelGrid{Vec3(0.0f), 1.0f, {static_cast<long>(std::max<size_t>(n, 1)), 1, 1}});
  slot.resize(n);
  for (size_t i = 0; i < n; ++i) slot[i] = light.occupy(static_cast<long>(i));
}

void LvoxelSet::append(const LvoxelSet& other) {
  if (other.size() == 0) return;
  if (size() == 0 && light.occupiedCount() == 0) {
    light = LvoxelLight(other.light.grid());
    light.setChannels(other.light.deltaLights(), other.light.phases());
    light.setCoefficients(other.light.coefficients());
  } else {
    LVOX_CHECK(light.grid() == other.light.grid(), "appending lvoxels of another grid");
  }
  auto cat = [](auto& a, const auto& b) { a.insert(a.end(), b.begin(), b.end()); };
  cat(position, other.position);
  cat(halfSize, other.halfSize);
  cat(sigmaA, other.sigmaA);
  cat(sigmaS, other.sigmaS);
  // Phase moments: kept per lvoxel as soon as one set has them (isotropic zeros else).
  if (!other.phaseMoments.empty() || !phaseMoments.empty()) {
    phaseMoments.resize(size() - other.size(), {});
    if (other.phaseMoments.empty())
      phaseMoments.resize(size(), {});
    else
      cat(phaseMoments, other.phaseMoments);
  }
  // Cut flags: kept per lvoxel as soon as one set has them (0, not cut, for the other's).
  if (!other.cut.empty() || !cut.empty()) {
    cut.resize(size() - other.size(), 0);
    if (other.cut.empty())
      cut.resize(size(), 0);
    else
      cat(cut, other.cut);
  }
  // Emission: kept per lvoxel as soon as one set has it (zeros for the other's).
  if (!other.emission.empty() || !emission.empty()) {
    emission.resize(size() - other.size(), RGB(0.0f));
    if (other.emission.empty())
      emission.resize(size(), RGB(0.0f));
    else
      cat(emission, other.emission);
  }
  for (uint32_t s : other.slot) slot.push_back(light.occupy(other.light.cellOfSlot(s)));
}

void LvoxelSet::permute(const std::vector<uint32_t>& order) {
  permuteArray(position, order);
  permuteArray(halfSize, order);
  permuteArray(sigmaA, order);
  permuteArray(sigmaS, order);
  if (!emission.empty()) permuteArray(emission, order);
  if (!phaseMoments.empty()) permuteArray(phaseMoments, order);
  if (!cut.empty()) permuteArray(cut, order);
  permuteArray(slot, order);
}

}  // namespace lvox
