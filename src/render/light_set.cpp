#include "src/render/light_set.h"

#include <algorithm>

#include "src/core/spherical_triangle.h"

namespace lvox {

LightSet::LightSet(const World& world, int areaSamples)
    : world_(world), areaSamples_(std::max(1, areaSamples)) {
  if (world.environmentMap && !world.environmentMap->black()) map_ = world.environmentMap.get();
  for (const Light& l : world.lights) {
    if (l.type == LightType::Environment && l.file.empty())
      environment_ += l.intensity;
    else if (l.type == LightType::Environment)
      continue;  // the map: its intensity scaled it on load
    else
      lights_.push_back(l);
  }
  const TriangleMesh& mesh = world.mesh;
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    if (!world.materials[mesh.triangleMaterial[t]].isEmissive()) continue;
    const Vec3 a = mesh.vertex(t, 0);
    const float area = 0.5f * length(cross(mesh.vertex(t, 1) - a, mesh.vertex(t, 2) - a));
    emissiveTriangles_.push_back(static_cast<uint32_t>(t));
    totalArea_ += area;
    areaCdf_.push_back(totalArea_);
  }
  for (float& c : areaCdf_) c /= totalArea_;
}

LightSample LightSet::sampleDelta(const Light& light, const Vec3& p) const {
  LightSample s;
  if (light.type == LightType::Directional) {
    s.wi = -light.direction;
    s.radiance = light.intensity;  // irradiance perpendicular to the light
    return s;
  }
  const Vec3 toLight = light.position - p;
  const float d2 = dot(toLight, toLight);
  if (!(d2 > 0.0f)) return s;  // the point is at the light: no defined direction
  s.distance = std::sqrt(d2);
  s.wi = toLight / s.distance;
  float factor = 1.0f / d2;
  if (light.type == LightType::Spot) factor *= light.spotFactor(-s.wi);
  s.radiance = light.intensity * factor;
  return s;
}

LightSample LightSet::sampleArea(const Vec3& p, Rng& rng) const {
  const uint32_t u = rng.next(), v = rng.next();
  return sampleArea(p, FixedPoint2{u, v});
}

namespace {

bool sampledBySolidAngle(double solidAngle) {
  return solidAngle >= LightSet::kMinSphericalSolidAngle &&
         solidAngle <= LightSet::kMaxSphericalSolidAngle;
}

}  // namespace

LightSample LightSet::sampleArea(const Vec3& p, FixedPoint2 point) const {
  LightSample s;
  // In double: 32 bits of u, so that where it fell in a small triangle's share still has
  // bits to spare.
  const double u = static_cast<double>(point.u) * 0x1p-32;
  const size_t i = std::min<size_t>(
      static_cast<size_t>(std::lower_bound(areaCdf_.begin(), areaCdf_.end(), u) - areaCdf_.begin()),
      emissiveTriangles_.size() - 1);
  const double lo = i > 0 ? areaCdf_[i - 1] : 0.0, hi = areaCdf_[i];
  const double within = hi > lo ? std::clamp((u - lo) / (hi - lo), 0.0, 1.0 - 0x1p-24) : 0.5;
  const uint32_t tri = emissiveTriangles_[i];
  const TriangleMesh& mesh = world_.mesh;
  const Vec3 a = mesh.vertex(tri, 0), b = mesh.vertex(tri, 1), c = mesh.vertex(tri, 2);
  const Vec3 n = normalize(cross(b - a, c - a));
  const SphericalTriangle seen(p, a, b, c);
  const RGB emission = world_.materials[mesh.triangleMaterial[tri]].emission;
  if (sampledBySolidAngle(seen.solidAngle())) {
    s.wi = seen.sample(within, fixedPointToUnit(point.v));
    const float cosLight = std::abs(dot(n, s.wi));  // emitters are two-sided
    s.distance = dot(a - p, n) / dot(s.wi, n);
    if (!(cosLight > 0.0f) || !(s.distance > 0.0f)) return s;
    // pdf: the triangle's share of the area, then 1 / its solid angle.
    s.pdf = static_cast<float>((hi - lo) / seen.solidAngle());
    s.radiance = emission * (1.0f / s.pdf);
    s.fromEmitter = true;
    return s;
  }
  float b1, b2;
  uniformTriangle(static_cast<float>(within), fixedPointToUnit(point.v), b1, b2);
  const Vec3 q = a * (1.0f - b1 - b2) + b * b1 + c * b2;
  const Vec3 toLight = q - p;
  const float d2 = dot(toLight, toLight);
  if (!(d2 > 0.0f)) return s;
  s.distance = std::sqrt(d2);
  s.wi = toLight / s.distance;
  const float cosLight = std::abs(dot(n, s.wi));
  // Area pdf 1/A over all emitters, converted to solid angle: d^2 / (A cos).
  s.radiance = emission * (cosLight * totalArea_ / d2);
  s.fromEmitter = true;
  s.pdf = d2 / (std::max(cosLight, 1e-8f) * totalArea_);
  return s;
}

float LightSet::emitterPdf(const Vec3& p, uint32_t triangle, float distance, float cosLight) const {
  const auto it = std::lower_bound(emissiveTriangles_.begin(), emissiveTriangles_.end(), triangle);
  if (it == emissiveTriangles_.end() || *it != triangle) return 0.0f;
  const auto i = static_cast<size_t>(it - emissiveTriangles_.begin());
  const double share = areaCdf_[i] - (i > 0 ? areaCdf_[i - 1] : 0.0);
  const TriangleMesh& mesh = world_.mesh;
  const SphericalTriangle seen(p, mesh.vertex(triangle, 0), mesh.vertex(triangle, 1),
                               mesh.vertex(triangle, 2));
  if (sampledBySolidAngle(seen.solidAngle())) return static_cast<float>(share / seen.solidAngle());
  return distance * distance / (std::max(cosLight, 1e-8f) * totalArea_);
}

}  // namespace lvox
