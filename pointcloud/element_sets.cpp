#include "pointcloud/lvoxels.h"
#include "pointcloud/surfels.h"

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

RGB LvoxelSet::sourceRadiance(size_t i) const {
  const RGB st = sigmaT(i);
  const RGB ls = directInScatter[i] + multiScatter[i];
  return {ratio(sigmaS[i].x, st.x) * ls.x, ratio(sigmaS[i].y, st.y) * ls.y,
          ratio(sigmaS[i].z, st.z) * ls.z};
}

void LvoxelSet::append(const LvoxelSet& other) {
  auto cat = [](auto& a, const auto& b) { a.insert(a.end(), b.begin(), b.end()); };
  cat(position, other.position);
  cat(halfSize, other.halfSize);
  cat(sigmaA, other.sigmaA);
  cat(sigmaS, other.sigmaS);
  cat(directInScatter, other.directInScatter);
  cat(multiScatter, other.multiScatter);
}

void LvoxelSet::permute(const std::vector<uint32_t>& order) {
  permuteArray(position, order);
  permuteArray(halfSize, order);
  permuteArray(sigmaA, order);
  permuteArray(sigmaS, order);
  permuteArray(directInScatter, order);
  permuteArray(multiScatter, order);
}

}  // namespace lvox
