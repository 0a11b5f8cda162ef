#pragma once
// Phase functions, normalised over the sphere (integral of p dw = 1). The argument is the
// cosine of the scattering angle between the propagation directions: light travelling
// along w_in that leaves along w_out has cosTheta = dot(w_in, w_out), so g > 0 scatters
// forward.
#include <string>
#include <string_view>

#include "src/core/math.h"
#include "src/core/names.h"

namespace lvox {

enum class PhaseKind { Isotropic, HenyeyGreenstein, Schlick };

inline constexpr Named<PhaseKind> kPhaseNames[] = {{PhaseKind::Isotropic, "isotropic"},
                                                   {PhaseKind::HenyeyGreenstein, "hg"},
                                                   {PhaseKind::Schlick, "schlick"}};

// "isotropic" | "hg" | "schlick"; throws InputError(file, field, ...) otherwise.
inline PhaseKind parsePhaseKind(std::string_view name, const std::string& file,
                                const std::string& field) {
  return parseNamed(name, kPhaseNames, "phase function", file, field);
}

struct PhaseFunction {
  PhaseKind kind = PhaseKind::Isotropic;
  float g = 0.0f;
  float k = 0.0f;  // Schlick's parameter, fitted to g: k = 1.55 g - 0.55 g^3

  // g = 0 is isotropic whatever the kind.
  static PhaseFunction make(PhaseKind kind, float g) {
    PhaseFunction p;
    p.kind = g == 0.0f ? PhaseKind::Isotropic : kind;
    p.g = p.kind == PhaseKind::Isotropic ? 0.0f : g;
    if (p.kind == PhaseKind::Schlick) p.k = 1.55f * g - 0.55f * g * g * g;
    for (int l = 0; l <= kMaxMoment; ++l) p.moments[l] = p.computeMoment(l);
    return p;
  }

  // Legendre moment chi_l = 2 pi * integral over [-1, 1] of p(mu) P_l(mu) dmu, l = 0..4:
  // 1, the mean cosine, ... The phase's expansion is p = sum (2l + 1) / (4 pi) chi_l P_l,
  // and it scales band l of the spherical harmonics of the light it scatters
  // (spherical_harmonics.h). Henyey-Greenstein: g^l exactly.
  float moment(int l) const { return moments[l]; }

  // The phase as a forward peak and a smooth rest, for a light field carried in bands
  // l < L (delta-M, Wiscombe 1977): a delta peak of weight f = chi_L is light that goes
  // on as if unscattered, and the rest, (p - f delta) / (1 - f), has the moments
  // (chi_l - f) / (1 - f). Its band-limited expansion stays nearly positive where the
  // plain one does not (Henyey-Greenstein at g = 0.8, three bands: the plain series
  // 1 + 3 g mu + 5 g^2 P_2(mu) reaches -0.6 at mu = 0, the rest's -0.054 at mu = -0.45).
  // Isotropic: f = 0, the rest is the phase itself.
  static constexpr int kMaxMoment = 4;
  struct Truncated {
    float forward = 0.0f;
    float moment[kMaxMoment] = {1.0f, 0.0f, 0.0f, 0.0f};  // of the rest, bands below `bands`
  };
  // For a light field carried in `bands` bands (l < bands <= kMaxMoment).
  Truncated truncated(int bands) const {
    Truncated t;
    t.forward = std::clamp(moments[bands], 0.0f, 0.999f);
    const float rest = 1.0f - t.forward;
    for (int l = 1; l < bands; ++l) t.moment[l] = (moments[l] - t.forward) / rest;
    return t;
  }
  float moments[kMaxMoment + 1] = {1.0f, 0.0f, 0.0f, 0.0f, 0.0f};  // chi_0.., set by make()

  float eval(float cosTheta) const {
    constexpr float inv4Pi = 1.0f / (4.0f * kPi);
    switch (kind) {
      case PhaseKind::Isotropic:
        return inv4Pi;
      case PhaseKind::HenyeyGreenstein: {
        const float denom = 1.0f + g * g - 2.0f * g * cosTheta;
        return inv4Pi * (1.0f - g * g) / (denom * std::sqrt(denom));
      }
      case PhaseKind::Schlick: {
        const float d = 1.0f - k * cosTheta;
        return inv4Pi * (1.0f - k * k) / (d * d);
      }
    }
    return inv4Pi;
  }

  // Samples the outgoing direction for light travelling along `wIn`; returns eval(cos).
  Vec3 sample(const Vec3& wIn, float u1, float u2, float& pdf) const {
    float cosTheta;
    switch (kind) {
      case PhaseKind::HenyeyGreenstein: {
        const float s = (1.0f - g * g) / (1.0f + g - 2.0f * g * u1);
        cosTheta = std::clamp((1.0f + g * g - s * s) / (2.0f * g), -1.0f, 1.0f);
        break;
      }
      case PhaseKind::Schlick: {
        // Inverse CDF of Schlick's function in cos: closed form.
        const float x = 2.0f * u1 - 1.0f;
        cosTheta = std::clamp((x + k) / (1.0f + k * x), -1.0f, 1.0f);
        break;
      }
      default:
        cosTheta = 1.0f - 2.0f * u1;
    }
    const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
    const float phi = 2.0f * kPi * u2;
    const Frame frame(wIn);
    pdf = eval(cosTheta);
    return frame.toWorld(Vec3(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta));
  }

  // chi_l: Henyey-Greenstein g^l; Schlick by quadrature (cold path: make() only).
  float computeMoment(int l) const {
    if (l == 0) return 1.0f;
    switch (kind) {
      case PhaseKind::Isotropic:
        return 0.0f;
      case PhaseKind::HenyeyGreenstein:
        return static_cast<float>(std::pow(static_cast<double>(g), l));
      case PhaseKind::Schlick:
        break;
    }
    // Midpoint rule in mu; Schlick's peak at mu = 1 has width about 1 - k, so 2^16 cells
    // resolve it to well under 1e-6 for k up to 0.99.
    constexpr int kCells = 1 << 16;
    double sum = 0.0;
    for (int i = 0; i < kCells; ++i) {
      const double mu = -1.0 + (i + 0.5) * (2.0 / kCells);
      const double mu2 = mu * mu;
      const double legendre = l == 1   ? mu
                              : l == 2 ? 0.5 * (3.0 * mu2 - 1.0)
                              : l == 3 ? 0.5 * mu * (5.0 * mu2 - 3.0)
                                       : (35.0 * mu2 * mu2 - 30.0 * mu2 + 3.0) / 8.0;
      const double d = 1.0 - k * mu;
      sum += (1.0 - static_cast<double>(k) * k) / (d * d) * legendre;
    }
    return static_cast<float>(0.5 * sum * (2.0 / kCells));  // 2 pi / (4 pi) = 1/2
  }
};

}  // namespace lvox
