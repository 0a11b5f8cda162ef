#pragma once
// Three independent colour channels (RGB) of any Real: the RTE solvers are templated on
// Real (double in tests, float in the renderer) and every channel has its own sigma_t.
#include <array>
#include <cmath>
#include <cstddef>

namespace lvox::rte {

template <class Real>
struct Channels {
  std::array<Real, 3> v{};

  constexpr Channels() = default;
  constexpr explicit Channels(Real s) : v{s, s, s} {}
  constexpr Channels(Real r, Real g, Real b) : v{r, g, b} {}

  constexpr Real& operator[](std::size_t i) { return v[i]; }
  constexpr const Real& operator[](std::size_t i) const { return v[i]; }

  constexpr Channels& operator+=(const Channels& o) {
    for (std::size_t i = 0; i < 3; ++i) v[i] += o.v[i];
    return *this;
  }
  friend constexpr Channels operator+(Channels a, const Channels& b) { return a += b; }
  friend constexpr Channels operator-(const Channels& a, const Channels& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
  }
  friend constexpr Channels operator*(const Channels& a, const Channels& b) {
    return {a[0] * b[0], a[1] * b[1], a[2] * b[2]};
  }
  friend constexpr Channels operator*(const Channels& a, Real s) {
    return {a[0] * s, a[1] * s, a[2] * s};
  }
  friend constexpr Channels operator*(Real s, const Channels& a) { return a * s; }

  constexpr Real maxComponent() const {
    Real m = v[0];
    for (std::size_t i = 1; i < 3; ++i) m = v[i] > m ? v[i] : m;
    return m;
  }
};

// One medium evaluation at a point of the ray: extinction and the full source
// J = sigma_a Le + sigma_s * (in-scattered radiance), already assembled by the caller.
template <class Real>
struct MediumSample {
  Channels<Real> sigmaT;
  Channels<Real> source;
};

}  // namespace lvox::rte
