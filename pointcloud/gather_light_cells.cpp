#include "pointcloud/gather_light_cells.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "pointcloud/gather.h"
#include "src/core/sampling.h"

namespace lvox {
namespace {

// Edge divisions at most: a triangle of 4096^2 cells is far finer than any surfel spacing
// a scene affords, and the cell index stays well inside 32 bits.
constexpr float kMaxDivisions = 4096.0f;

// The first lower (upper) cell of row i: rows hold m - i (m - 1 - i) cells.
uint32_t lowerRowStart(uint32_t m, uint32_t i) { return i * m - i * (i - 1) / 2; }
uint32_t upperRowStart(uint32_t m, uint32_t i) { return i * (m - 1) - i * (i - 1) / 2; }

// The row i whose cells [start(i), start(i + 1)) hold `index`, for rows of n, n - 1, ...
// cells: the root of i^2 - (2 n + 1) i + 2 index = 0, corrected for rounding.
template <class Start>
uint32_t rowOf(uint32_t n, uint32_t index, Start start) {
  const double b = 2.0 * n + 1.0;
  auto i = static_cast<uint32_t>(
      std::max(0.0, std::floor((b - std::sqrt(std::max(0.0, b * b - 8.0 * index))) / 2)));
  while (i > 0 && start(i) > index) --i;
  while (start(i + 1) <= index) ++i;
  return i;
}

float channelMean(const RGB& c) { return (c.x + c.y + c.z) / 3.0f; }

// cos(a - b) from the cosines and sines of angles a, b in [0, pi]; 1 where a <= b.
float cosOfDifference(float cosA, float sinA, float cosB, float sinB) {
  return cosA >= cosB ? 1.0f : cosA * cosB + sinA * sinB;
}
float sinOf(float cosine) { return std::sqrt(std::max(0.0f, 1.0f - cosine * cosine)); }

}  // namespace

uint32_t GatherLightCells::divisionsOf(const Vec3& a, const Vec3& b, const Vec3& c, float step) {
  const float longest = std::max({length(b - a), length(c - b), length(a - c)});
  // An equilateral triangle of area A has sides sqrt(4 A / sqrt(3)): a sliver gets at most
  // four times the divisions of that triangle, not its long edge's.
  const float area = 0.5f * length(cross(b - a, c - a));
  const float cap = 4.0f * std::max(1.0f, std::ceil(std::sqrt(2.3094f * area) / step));
  const float m = std::ceil(std::min(longest / step, cap));
  return static_cast<uint32_t>(std::clamp(std::isfinite(m) ? m : 1.0f, 1.0f, kMaxDivisions));
}

size_t GatherLightCells::cellsFor(const TriangleMesh& mesh, float step) {
  size_t cells = 0;
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    const uint32_t m = divisionsOf(mesh.vertex(t, 0), mesh.vertex(t, 1), mesh.vertex(t, 2), step);
    cells += static_cast<size_t>(m) * m;
  }
  return cells;
}

uint32_t GatherLightCells::cellOf(uint32_t m, float b1, float b2) {
  const float fm = static_cast<float>(m);
  const float u = std::clamp(b1, 0.0f, 1.0f) * fm, v = std::clamp(b2, 0.0f, 1.0f) * fm;
  const uint32_t i = std::min(static_cast<uint32_t>(u), m - 1);
  const uint32_t j = std::min(static_cast<uint32_t>(v), m - 1 - i);
  const bool upper = u - static_cast<float>(i) + v - static_cast<float>(j) > 1.0f && i + j + 2 <= m;
  return upper ? m * (m + 1) / 2 + upperRowStart(m, i) + j : lowerRowStart(m, i) + j;
}

size_t GatherLightCells::bytesFor(size_t cells, size_t triangles) {
  // Per cell two sides' light index; per light its key, region and cumulative power.
  return cells * 2 * (sizeof(uint32_t) + 2 * sizeof(uint32_t) + sizeof(double)) +
         triangles * sizeof(Triangle);
}

GatherLightCells::GatherLightCells(const TriangleMesh& mesh, const PointCloud& cloud,
                                   const GatherOptions& options, float step)
    : mesh_(&mesh) {
  const size_t n = mesh.triangleCount();
  triangles_.resize(n);
  for (size_t t = 0; t < n; ++t) {
    const Vec3 a = mesh.vertex(t, 0), b = mesh.vertex(t, 1), c = mesh.vertex(t, 2);
    const uint32_t m = divisionsOf(a, b, c, step);
    const Vec3 face = cross(b - a, c - a);
    const float area = 0.5f * length(face);
    // A triangle without area is never hit: its cells keep no power.
    triangles_[t] = {static_cast<uint32_t>(cells_), m,
                     area / static_cast<float>(static_cast<size_t>(m) * m),
                     area > 0.0f ? normalize(face) : Vec3(0, 0, 1)};
    cells_ += static_cast<size_t>(m) * m;
    if (2 * cells_ >= kNone) throw std::length_error("the gathers' light cells exceed 2^31");
  }
  std::vector<float> power(2 * cells_, 0.0f);
  const CloudSurfels& surfels = cloud.surfels();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 64), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t < r.end(); ++t) {
      const Triangle& tri = triangles_[t];
      if (!(tri.cellArea > 0.0f)) continue;
      for (uint32_t k = 0; k < tri.m * tri.m; ++k) {
        // The cell's centre: its corners' mean.
        const Sample centre = pointIn(static_cast<uint32_t>(t), k, 1.0f / 3.0f, 1.0f / 3.0f);
        for (int side = 0; side < 2; ++side) {  // either side may face a receiver
          SurfaceHit hit;
          hit.triangle = static_cast<uint32_t>(t);
          hit.point = centre.point;
          hit.b1 = centre.b1;
          hit.b2 = centre.b2;
          hit.normal = side == 0 ? tri.normal : -tri.normal;
          // The shading normal on the hit's side, as the tracer gives it.
          hit.shading = hit.normal;
          if (!mesh.normals.empty()) {
            const Vec3 shading = mesh.shadingNormalAt(t, centre.b1, centre.b2);
            hit.shading = dot(shading, hit.normal) < 0.0f ? -shading : shading;
          }
          RGB l(0.0f);
          if (options.hitLight) l += options.hitLight->reflected(hit);
          const long s = options.tracesSurfaces() ? options.surfelAt(hit) : -1;
          if (s >= 0) {
            const auto i = static_cast<uint32_t>(s);
            l += dot(surfels.normal(i), hit.normal) > 0.0f ? surfels.radianceFront[i]
                                                           : surfels.radianceBack[i];
          }
          const float p = channelMean(l) * tri.cellArea;
          if (std::isfinite(p) && p > 0.0f) power[2 * (tri.first + k) + side] = p;
        }
      }
    }
  });
  std::vector<Vec3> position, normal;
  std::vector<float> lightPower;
  std::vector<uint32_t> key;
  for (uint32_t t = 0; t < n; ++t) {
    const Triangle& tri = triangles_[t];
    for (uint32_t k = 0; k < tri.m * tri.m; ++k)
      for (int side = 0; side < 2; ++side) {
        const uint32_t kk = 2 * (tri.first + k) + static_cast<uint32_t>(side);
        if (!(power[kk] > 0.0f)) continue;
        position.push_back(pointIn(t, k, 1.0f / 3.0f, 1.0f / 3.0f).point);
        normal.push_back(side == 0 ? tri.normal : -tri.normal);
        lightPower.push_back(power[kk]);
        key.push_back(kk);
      }
  }
  buildRegions(position, normal, lightPower, key);
}

void GatherLightCells::buildRegions(const std::vector<Vec3>& position,
                                    const std::vector<Vec3>& normal,
                                    const std::vector<float>& power,
                                    const std::vector<uint32_t>& key) {
  const size_t count = key.size();
  if (count == 0) return;
  // Six groups by the axis and sign the side faces most, then median splits along the
  // longest side of the box down to `leaf` lights: leaves hold more than leaf / 2, so there
  // are at most 2 count / leaf + 6 <= kMaxRegions of them.
  std::vector<uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0u);
  auto group = [&](uint32_t i) {
    const Vec3& v = normal[i];
    const int axis = std::abs(v.x) >= std::abs(v.y) && std::abs(v.x) >= std::abs(v.z) ? 0
                     : std::abs(v.y) >= std::abs(v.z)                                 ? 1
                                                                                      : 2;
    return 2 * axis + (v[axis] < 0.0f ? 1 : 0);
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return group(a) < group(b); });
  const size_t leaf =
      std::max<size_t>(1, (2 * count + kMaxRegions - 7) / static_cast<size_t>(kMaxRegions - 6));
  std::vector<std::pair<size_t, size_t>> leaves;
  auto split = [&](auto&& self, size_t begin, size_t end) -> void {
    if (end - begin <= leaf) {
      leaves.emplace_back(begin, end);
      return;
    }
    Bounds3 box;
    for (size_t k = begin; k < end; ++k) box.extend(position[order[k]]);
    const Vec3 extent = box.diagonal();
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0
                     : extent.y >= extent.z                       ? 1
                                                                  : 2;
    const size_t mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + static_cast<ptrdiff_t>(begin),
                     order.begin() + static_cast<ptrdiff_t>(mid),
                     order.begin() + static_cast<ptrdiff_t>(end), [&](uint32_t a, uint32_t b) {
                       return position[a][axis] < position[b][axis] ||
                              (position[a][axis] == position[b][axis] && a < b);
                     });
    self(self, begin, mid);
    self(self, mid, end);
  };
  size_t begin = 0;
  while (begin < count) {
    size_t end = begin;
    while (end < count && group(order[end]) == group(order[begin])) ++end;
    split(split, begin, end);
    begin = end;
  }
  entryKey_.resize(count);
  entryCdf_.assign(count + 1, 0.0);
  regionOf_.resize(count);
  entryOfSide_.assign(2 * cells_, kNone);
  for (const auto& [first, end] : leaves) {
    Region r;
    r.first = static_cast<uint32_t>(first);
    r.end = static_cast<uint32_t>(end);
    Bounds3 box;
    Vec3 sum(0.0f);
    float reach = 0.0f;  // the cells' own size beyond their centres
    for (size_t k = first; k < end; ++k) {
      const uint32_t i = order[k];
      box.extend(position[i]);
      sum += normal[i] * power[i];
      r.power += power[i];
      const float cellArea = triangles_[triangleOfCell(key[i] / 2)].cellArea;
      reach = std::max(reach, std::sqrt(2.0f * cellArea));
      entryKey_[k] = key[i];
      entryCdf_[k + 1] = entryCdf_[k] + static_cast<double>(power[i]);
      regionOf_[k] = static_cast<uint32_t>(regions_.size());
      entryOfSide_[key[i]] = static_cast<uint32_t>(k);
    }
    r.centre = box.center();
    r.radius = 0.5f * length(box.diagonal()) + reach;
    const float axisLength = length(sum);
    r.axis = axisLength > 0.0f ? sum / axisLength : Vec3(0, 0, 1);
    r.cosSpread = axisLength > 0.0f ? 1.0f : -1.0f;
    for (size_t k = first; k < end; ++k)
      r.cosSpread = std::min(r.cosSpread, dot(r.axis, normal[order[k]]));
    r.sinSpread = sinOf(r.cosSpread);
    regions_.push_back(r);
  }
}

float GatherLightCells::importance(const Region& r, const Vec3& p, const Vec3& n) const {
  const Vec3 toP = p - r.centre;
  const float d2 = dot(toP, toP);
  if (d2 <= r.radius * r.radius) return r.power / std::max(r.radius * r.radius, 1e-12f);
  const float d = std::sqrt(d2);
  const Vec3 w = toP / d;
  // The box subtends at most the bounding sphere's angle theta_b about w.
  const float sinB = r.radius / d, cosB = sinOf(sinB);
  // At the lights: the angle between their normals and w is at least
  // theta_w - theta_spread - theta_b.
  const float cosW = dot(r.axis, w);
  const float cosA = cosOfDifference(cosW, sinOf(cosW), r.cosSpread, r.sinSpread);
  const float cosLight = cosOfDifference(cosA, sinOf(cosA), cosB, sinB);
  if (!(cosLight > 0.0f)) return 0.0f;
  // At the receiver: the angle between n and -w is at least theta_i - theta_b.
  const float cosI = -dot(n, w);
  const float cosReceiver = cosOfDifference(cosI, sinOf(cosI), cosB, sinB);
  if (!(cosReceiver > 0.0f)) return 0.0f;
  return r.power * cosLight * cosReceiver / d2;
}

GatherLightCells::View GatherLightCells::view(const Vec3& p, const Vec3& n) const {
  View v;
  v.regions_ = static_cast<int>(regions_.size());
  float sum = 0.0f;
  for (size_t k = 0; k < regions_.size(); ++k) {
    const float w = importance(regions_[k], p, n);
    sum += std::isfinite(w) ? w : 0.0f;
    v.cdf_[k + 1] = sum;
  }
  if (!(sum > 0.0f) || !std::isfinite(sum)) {
    v.cdf_.fill(0.0f);
    return v;
  }
  for (size_t k = 1; k <= regions_.size(); ++k) v.cdf_[k] /= sum;  // the last is exactly 1
  return v;
}

uint32_t GatherLightCells::triangleOfCell(uint32_t cell) const {
  const auto owner = std::upper_bound(triangles_.begin(), triangles_.end(), cell,
                                      [](uint32_t c, const Triangle& t) { return c < t.first; });
  return static_cast<uint32_t>(owner - triangles_.begin() - 1);
}

GatherLightCells::Sample GatherLightCells::pointIn(uint32_t t, uint32_t cell, float beta1,
                                                   float beta2) const {
  const uint32_t m = triangles_[t].m;
  const uint32_t lowerCells = m * (m + 1) / 2;
  float u, v;
  if (cell < lowerCells) {  // corners (i, j), (i + 1, j), (i, j + 1)
    const uint32_t i = rowOf(m, cell, [m](uint32_t r) { return lowerRowStart(m, r); });
    const uint32_t j = cell - lowerRowStart(m, i);
    u = static_cast<float>(i) + beta1;
    v = static_cast<float>(j) + beta2;
  } else {  // corners (i + 1, j + 1), (i, j + 1), (i + 1, j)
    const uint32_t index = cell - lowerCells;
    const uint32_t i = rowOf(m - 1, index, [m](uint32_t r) { return upperRowStart(m, r); });
    const uint32_t j = index - upperRowStart(m, i);
    u = static_cast<float>(i + 1) - beta1;
    v = static_cast<float>(j + 1) - beta2;
  }
  Sample s;
  s.triangle = t;
  s.b1 = u / static_cast<float>(m);
  s.b2 = v / static_cast<float>(m);
  const Vec3 v0 = mesh_->vertex(t, 0);
  s.point = v0 + (mesh_->vertex(t, 1) - v0) * s.b1 + (mesh_->vertex(t, 2) - v0) * s.b2;
  s.normal = triangles_[t].normal;
  return s;
}

GatherLightCells::Sample GatherLightCells::sample(const View& view, float u1, float u2, float u3,
                                                  float u4) const {
  if (view.empty()) return {};
  // The last region whose cumulative weight is at most u1: one of positive weight.
  const float* cdf = view.cdf_.data();
  const float* it = std::upper_bound(cdf, cdf + view.regions_, std::min(u1, 0.99999994f));
  const auto region = static_cast<uint32_t>(std::max<ptrdiff_t>(it - cdf - 1, 0));
  Sample s = pointOf(region, u2, u3, u4);
  s.pdfArea *= cdf[region + 1] - cdf[region];
  return s;
}

GatherLightCells::Sample GatherLightCells::pointOf(uint32_t region, float u1, float u2,
                                                   float u3) const {
  const Region& r = regions_[region];
  const double lo = entryCdf_[r.first], span = entryCdf_[r.end] - lo;
  const auto e = std::upper_bound(entryCdf_.begin() + r.first, entryCdf_.begin() + r.end,
                                  lo + static_cast<double>(u1) * span);
  const auto entry = static_cast<uint32_t>(
      std::clamp<ptrdiff_t>(e - entryCdf_.begin() - 1, r.first, static_cast<ptrdiff_t>(r.end) - 1));
  const uint32_t cell = entryKey_[entry] / 2;
  const uint32_t t = triangleOfCell(cell);
  float beta1, beta2;
  uniformTriangle(u2, u3, beta1, beta2);
  Sample s = pointIn(t, cell - triangles_[t].first, beta1, beta2);
  if (entryKey_[entry] & 1u) s.normal = -s.normal;
  s.pdfArea = static_cast<float>(densityInRegion(entry, triangles_[t].cellArea));
  return s;
}

double GatherLightCells::densityInRegion(uint32_t entry, float cellArea) const {
  const Region& r = regions_[regionOf_[entry]];
  const double share =
      (entryCdf_[entry + 1] - entryCdf_[entry]) / (entryCdf_[r.end] - entryCdf_[r.first]);
  return share / static_cast<double>(cellArea);
}

float GatherLightCells::pdfArea(const View& view, uint32_t triangle, float b1, float b2,
                                const Vec3& towards) const {
  if (triangle >= triangles_.size() || view.empty()) return 0.0f;
  const Triangle& tri = triangles_[triangle];
  if (!(tri.cellArea > 0.0f)) return 0.0f;
  const uint32_t cell = tri.first + cellOf(tri.m, b1, b2);
  const uint32_t entry = entryOfSide_[2 * cell + (dot(tri.normal, towards) > 0.0f ? 0u : 1u)];
  if (entry == kNone) return 0.0f;
  const uint32_t region = regionOf_[entry];
  return static_cast<float>(static_cast<double>(view.cdf_[region + 1] - view.cdf_[region]) *
                            densityInRegion(entry, tri.cellArea));
}

size_t GatherLightCells::memoryBytes() const {
  return triangles_.capacity() * sizeof(Triangle) + entryKey_.capacity() * sizeof(uint32_t) +
         entryCdf_.capacity() * sizeof(double) + entryOfSide_.capacity() * sizeof(uint32_t) +
         regionOf_.capacity() * sizeof(uint32_t) + regions_.capacity() * sizeof(Region);
}

}  // namespace lvox
