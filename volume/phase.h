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
    return p;
  }

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
};

}  // namespace lvox
