#include "volume/media/medium.h"

#include <cmath>

namespace lvox {

float Medium::densityAt(const Vec3& p) const {
  switch (type) {
    case MediumType::Homogeneous:
      return bounds.contains(p) ? 1.0f : 0.0f;
    case MediumType::Procedural: {
      if (!bounds.contains(p)) return 0.0f;
      switch (procedural) {
        case ProceduralKind::Constant:
          return 1.0f;
        case ProceduralKind::LinearRamp:
          return std::max(0.0f, 1.0f + dot(gradient, p - bounds.lo));
        case ProceduralKind::GaussianBlob: {
          const Vec3 d = p - center;
          return std::exp(-dot(d, d) / (2.0f * radius * radius));
        }
        case ProceduralKind::Noise: {
          // A smooth, deterministic, high-frequency field in [0, 1].
          const float w = 2.0f * kPi * frequency;
          return 0.5f +
                 0.5f * std::sin(w * p.x) * std::sin(w * p.y + 1.3f) * std::sin(w * p.z + 2.1f);
        }
      }
      return 0.0f;
    }
    case MediumType::Vdb:
      return density->sample(p, interpolation);
  }
  return 0.0f;
}

MediumCoefficients Medium::at(const Vec3& p) const {
  MediumCoefficients c;
  const float d = densityAt(p);
  if (d <= 0.0f) return c;
  if (type == MediumType::Vdb) {
    const float sigmaT = densityScale * d;
    c.sigmaS = albedo * sigmaT;
    c.sigmaA = RGB(sigmaT) - c.sigmaS;
  } else {
    c.sigmaA = sigmaA * d;
    c.sigmaS = sigmaS * d;
  }
  if (!isBlack(emission)) {
    float scale = 1.0f;
    if (emissionGrid) scale = emissionGrid->sample(p, interpolation);
    c.source = c.sigmaA * emission * scale;
  }
  if (temperatureGrid) {
    const float kelvin = temperature * temperatureGrid->sample(p, interpolation);
    c.source += c.sigmaA * (*blackbody)(kelvin)*blackbodyIntensity;
  }
  return c;
}

RGB Medium::majorant() const {
  switch (type) {
    case MediumType::Homogeneous:
      return sigmaA + sigmaS;
    case MediumType::Procedural: {
      float maxDensity = 1.0f;
      if (procedural == ProceduralKind::LinearRamp) {
        const Vec3 d = bounds.diagonal();
        maxDensity = 1.0f + std::max(0.0f, gradient.x) * d.x + std::max(0.0f, gradient.y) * d.y +
                     std::max(0.0f, gradient.z) * d.z;
      }
      return (sigmaA + sigmaS) * maxDensity;
    }
    case MediumType::Vdb:
      // The B-spline and trilinear stencils never exceed the largest voxel.
      return RGB(densityScale * density->maxValue());
  }
  return RGB(0.0f);
}

void Medium::intervals(const Ray& ray, float tmin, float tmax,
                       std::vector<std::pair<float, float>>& out) const {
  if (type == MediumType::Vdb) {
    density->intervals(ray, tmin, tmax, out);
    return;
  }
  Ray r = ray;
  r.tmin = tmin;
  r.tmax = tmax;
  float t0, t1;
  if (bounds.intersect(r, t0, t1) && t1 > t0) out.emplace_back(t0, t1);
}

size_t Medium::memoryBytes() const {
  size_t bytes = sizeof(Medium);
  if (density) bytes += density->memoryBytes();
  if (emissionGrid) bytes += emissionGrid->memoryBytes();
  if (temperatureGrid) bytes += temperatureGrid->memoryBytes();
  return bytes;
}

}  // namespace lvox
