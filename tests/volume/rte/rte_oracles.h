#pragma once
// Test-only problems with analytic answers (oracles.md 2.1-2.3, 2.7) and an independent
// adaptive quadrature (long double, Gauss-Legendre 5 vs 10 points with bisection) for the
// point-light oracle. Nothing here uses the solvers under test.
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include "volume/rte/channels.h"

namespace lvox::rte::test {

using C3 = Channels<double>;
using Sample = MediumSample<double>;
inline constexpr double kPi = std::numbers::pi;

// y' = -sigma y per channel, no source.
struct Decay {
  C3 sigma;
  Sample eval(double) const { return {sigma, C3(0.0)}; }
};

// (a) slab: homogeneous sigma_t, directional light through length s0 + kappa t of medium.
struct Slab {
  double sigmaT = 1.3, sigmaS = 0.9, E = 2.0, s0 = 0.4, kappa = 0.6;
  double phase = 1.0 / (4.0 * kPi);
  double sourceAt(double t) const {
    return sigmaS * phase * E * std::exp(-sigmaT * (s0 + kappa * t));
  }
  Sample eval(double t) const { return {C3(sigmaT), C3(sourceAt(t))}; }
  double exact(double d, double lbg) const {
    const double k1 = sigmaT * (1.0 + kappa);
    return std::exp(-sigmaT * d) * lbg +
           sigmaS * phase * E * std::exp(-sigmaT * s0) * (-std::expm1(-k1 * d)) / k1;
  }
  // Exact (T, Q) after [t, t + h] restarted from (T0, Q0): for local-error checks.
  void exactStep(double t, double h, double T0, double Q0, double& T1, double& Q1) const {
    const double k1 = sigmaT * (1.0 + kappa);
    T1 = T0 * std::exp(-sigmaT * h);
    // int_t^{t+h} e^{-sigma (u - t)} S(u) du with S(u) = S(t) e^{-sigma kappa (u - t)}
    Q1 = Q0 + T0 * sourceAt(t) * (-std::expm1(-k1 * h)) / k1;
  }
};

// Constant sigma and a source that is switched off at tStar (a sharp shadow edge: C0).
struct ShadowEdge {
  double sigmaT = 1.3, tStar = 0.8123, J = 1.0;
  Sample eval(double t) const { return {C3(sigmaT), C3(t < tStar ? J : 0.0)}; }
  double exact(double d, double lbg) const {
    return J * (-std::expm1(-sigmaT * std::min(tStar, d))) / sigmaT + std::exp(-sigmaT * d) * lbg;
  }
};

// (c) Gaussian blob of extinction on the ray o = 0, w = x.
struct GaussianBlob {
  double sigma0 = 3.0, s = 0.3, delta = 1.2, h2 = 0.1 * 0.1 + 0.2 * 0.2;
  Sample eval(double t) const {
    const double d2 = (t - delta) * (t - delta) + h2;
    return {C3(sigma0 * std::exp(-d2 / (2 * s * s))), C3(0.0)};
  }
  double tau(double d) const {
    return sigma0 * std::exp(-h2 / (2 * s * s)) * s * std::sqrt(kPi / 2) *
           (std::erf((d - delta) / (s * std::sqrt(2.0))) - std::erf(-delta / (s * std::sqrt(2.0))));
  }
};

// Emission-absorption: sigma_a = 2 + sin 7t, source sigma_a Le. L = Le + (Lbg - Le) e^-tau.
struct EmissionAbsorption {
  double le = 0.8, omega = 7.0;
  Sample eval(double t) const {
    const double sa = 2.0 + std::sin(omega * t);
    return {C3(sa), C3(sa * le)};
  }
  double exact(double d, double lbg) const {
    const double tau = 2.0 * d + (1.0 - std::cos(omega * d)) / omega;
    return le + (lbg - le) * std::exp(-tau);
  }
};

// (b) isotropic point light in an unbounded homogeneous medium, camera at 0 looking along x.
struct PointLight {
  double cx = 2, cy = 0.5, cz = 0, sigmaT = 0.7, sigmaS = 0.4, I = 10;
  double delta() const { return cx; }
  double h() const { return std::sqrt(cy * cy + cz * cz); }
  Sample eval(double t) const {
    const double dx = cx - t, r2 = dx * dx + cy * cy + cz * cz, r = std::sqrt(r2);
    return {C3(sigmaT), C3(sigmaS / (4 * kPi) * I * std::exp(-sigmaT * r) / r2)};
  }
};

// Adaptive Gauss-Legendre (5 vs 10 points, bisection) in long double.
inline long double adaptiveGaussLegendre(const std::function<long double(long double)>& f,
                                         long double a, long double b, long double tol,
                                         int depth = 0) {
  static const long double x5[5] = {
      0.0L, 0.538469310105683091036314420700208805L, -0.538469310105683091036314420700208805L,
      0.906179845938663992797626878299392965L, -0.906179845938663992797626878299392965L};
  static const long double w5[5] = {
      0.568888888888888888888888888888888889L, 0.478628670499366468041291514835638192L,
      0.478628670499366468041291514835638192L, 0.236926885056189087514264040719917363L,
      0.236926885056189087514264040719917363L};
  auto rule = [&](long double lo, long double hi) {
    const long double m = (lo + hi) / 2, r = (hi - lo) / 2;
    long double s = 0;
    for (int i = 0; i < 5; ++i) s += w5[i] * f(m + r * x5[i]);
    return s * r;
  };
  const long double m = (a + b) / 2;
  const long double whole = rule(a, b), halves = rule(a, m) + rule(m, b);
  if (std::fabs(whole - halves) <= tol || depth > 40) return halves;
  return adaptiveGaussLegendre(f, a, m, tol / 2, depth + 1) +
         adaptiveGaussLegendre(f, m, b, tol / 2, depth + 1);
}

// L_ss of (b) through the equiangular substitution t - Delta = h tan u (smooth integrand).
inline double pointLightOracle(const PointLight& p, double d) {
  const long double D = p.delta(), h = p.h();
  const long double ua = std::atan(-D / h), ub = std::atan((d - D) / h);
  auto g = [&](long double u) {
    const long double t = D + h * std::tan(u), r = h / std::cos(u);
    return static_cast<long double>(p.sigmaS) / (4 * kPi) * p.I * std::exp(-p.sigmaT * t) *
           std::exp(-p.sigmaT * r) / h;
  };
  return static_cast<double>(adaptiveGaussLegendre(g, ua, ub, 1e-16L));
}

// Least-squares slope of log(y) against log(x).
inline double logLogSlope(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace lvox::rte::test
