#pragma once
// Quadrature rules on the integral form L = int T(t0,t) J(t) dt + T(t0,t1) Lbg. The
// transmittance at every sample comes from the same samples' sigma by a rule of matching
// order, accumulated along the ray (Munoz 2014, "homogeneous versus heterogeneous": the
// media are treated as heterogeneous, T is never taken from a closed form):
//   rectangle: T *= exp(-sigma(t_left) h) (order 1, classic ray marching);
//   simpson / adaptive-simpson: tau at the end by Simpson, at the midpoint by integrating
//     the panel's quadratic interpolant of sigma (order 4);
//   gauss-kronrod: tau at each of the 15 nodes by integrating the degree-14 interpolant;
//   monte-carlo: tau by the trapezoid rule through the sorted jittered samples (bias O(h^2),
//     below the N^-3/2 noise of jittered sampling).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "src/core/rng.h"
#include "volume/rte/fixed_step.h"
#include "volume/rte/state.h"

namespace lvox::rte {

// The 15-point Kronrod rule with its embedded 7-point Gauss rule on [-1, 1] (QUADPACK qk15),
// nodes ascending; gaussWeights are 0 at the Kronrod-only nodes.
struct GaussKronrod15 {
  std::array<double, 15> nodes, kronrodWeights, gaussWeights;
  std::array<std::array<double, 15>, 15> partial;  // int_{-1}^{x_i} l_j(x) dx (Lagrange l_j)
};

inline const GaussKronrod15& gaussKronrod15() {
  static const GaussKronrod15 rule = [] {
    constexpr double xgk[8] = {
        0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
        0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
        0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
        0.207784955007898467600689403773245, 0.0};
    constexpr double wgk[8] = {
        0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
        0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
        0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
        0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
    constexpr double wg[4] = {
        0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
        0.381830050505118944950369775488975, 0.417959183673469387755102040816327};
    GaussKronrod15 r{};
    for (int i = 0; i < 8; ++i) {
      r.nodes[i] = -xgk[i];
      r.nodes[14 - i] = xgk[i];
      r.kronrodWeights[i] = r.kronrodWeights[14 - i] = wgk[i];
      const double g = i % 2 == 1 ? wg[i / 2] : 0.0;
      r.gaussWeights[i] = r.gaussWeights[14 - i] = g;
    }
    auto lagrange = [&r](int j, double x) {
      double p = 1.0;
      for (int k = 0; k < 15; ++k)
        if (k != j) p *= (x - r.nodes[k]) / (r.nodes[j] - r.nodes[k]);
      return p;
    };
    // l_j has degree 14; K15 mapped onto [-1, x_i] integrates it exactly.
    for (int i = 0; i < 15; ++i)
      for (int j = 0; j < 15; ++j) {
        const double half = 0.5 * (r.nodes[i] + 1.0);
        double sum = 0.0;
        for (int k = 0; k < 15; ++k)
          sum += r.kronrodWeights[k] * lagrange(j, -1.0 + half * (r.nodes[k] + 1.0));
        r.partial[i][j] = half * sum;
      }
    return r;
  }();
  return rule;
}

// Left-point ray marching: sigma and J are taken at the step's left end, and the
// attenuation inside the step is integrated exactly, Q += T J (1 - e^{-sigma h}) / sigma,
// as renderers march. Still order 1, but bounded by J/sigma for any h (the pure left rule
// T J h overshoots by sigma h on optically thick steps).
template <class Real, class Eval>
void rectangleRule(Eval& eval, RayState<Real>& s, Real a, Real b, const JitteredGrid<Real>& grid) {
  Real t = a;
  while (t < b) {
    const Real tEnd = grid.next(t, b);
    if (!eval.canAfford(1)) return finishGracefully(eval, s, t, b);
    const MediumSample<Real> m = eval(t);
    constantCoefficientStep(s, m, m, tEnd - t);
    ++eval.counts().steps;
    t = tEnd;
  }
}

// Simpson panel [t, t + h] from samples at its ends and midpoint: returns nothing, adds the
// panel's contribution and attenuation to the state.
template <class Real>
struct SimpsonPanel {
  Channels<Real> q;    // int_panel T(t_start, t) J dt by Simpson (relative to T at start)
  Channels<Real> tau;  // Simpson optical depth across the panel
  Channels<Real> qTrap, tauTrap;  // the nested trapezoid estimates (error control)
};

template <class Real>
SimpsonPanel<Real> simpsonPanel(const MediumSample<Real>& a, const MediumSample<Real>& m,
                                const MediumSample<Real>& b, Real h) {
  SimpsonPanel<Real> p;
  for (std::size_t c = 0; c < 3; ++c) {
    const Real tau = h / 6 * (a.sigmaT[c] + 4 * m.sigmaT[c] + b.sigmaT[c]);
    const Real tauMid =
        std::clamp(h / 24 * (5 * a.sigmaT[c] + 8 * m.sigmaT[c] - b.sigmaT[c]), Real(0), tau);
    p.tau[c] = tau;
    p.q[c] =
        h / 6 * (a.source[c] + 4 * m.source[c] * std::exp(-tauMid) + b.source[c] * std::exp(-tau));
    p.tauTrap[c] = h / 2 * (a.sigmaT[c] + b.sigmaT[c]);
    p.qTrap[c] = h / 2 * (a.source[c] + b.source[c] * std::exp(-p.tauTrap[c]));
  }
  return p;
}

template <class Real>
void applyPanel(RayState<Real>& s, const Channels<Real>& q, const Channels<Real>& tau) {
  s.Q += q * s.scale * s.T;
  for (std::size_t c = 0; c < 3; ++c) s.T[c] *= std::exp(-tau[c]);
  s.settle();
}

// Composite Simpson as a fixed-step stepper, so the fixed-step driver's stiffness handling
// applies: a panel with sigma h > 2 is split (a stability event) or replaced by an exact
// constant-coefficient step.
template <class Real>
class SimpsonStepper {
 public:
  uint64_t evalsPerStep() const { return 2; }
  void restart() {}
  template <class Eval>
  StepAttempt<Real> attempt(RayState<Real>& s, Real t, Real tEnd, const MediumSample<Real>& start,
                            Eval& eval) {
    const Real h = tEnd - t;
    StepAttempt<Real> out{true, start.sigmaT.maxComponent(), Real(2)};
    if (out.sigmaMax * h > out.limit * Real(1.000001)) return out.stable = false, out;
    const MediumSample<Real> mid = eval(t + h / 2);
    out.hasEnd = true;
    out.end = eval(tEnd);
    out.sigmaMax =
        std::max({out.sigmaMax, mid.sigmaT.maxComponent(), out.end.sigmaT.maxComponent()});
    if (out.sigmaMax * h > out.limit * Real(1.000001)) return out.stable = false, out;
    const SimpsonPanel<Real> p = simpsonPanel(start, mid, out.end, h);
    applyPanel(s, p.q, p.tau);
    return out;
  }
};

// Absolute error of a panel from its two nested estimates: error in Q plus error in T, both
// weighted by the true transmittance at the panel start.
template <class Real>
Real panelError(const RayState<Real>& s, const Channels<Real>& dq, const Channels<Real>& dtau) {
  Real err = Real(0);
  for (std::size_t c = 0; c < 3; ++c)
    err = std::max(err, s.T[c] * s.scale[c] * (std::abs(dq[c]) + std::abs(dtau[c])));
  return err;
}

// Nested Simpson/trapezoid (Munoz 2014): a panel is accepted when |Simpson - trapezoid| <=
// tol * (panel length / segment length), else halved (2 new evaluations, the 3 old reused).
// The accepted value is Simpson's. Panels are processed left to right so T is known.
template <class Real, class Eval>
void adaptiveSimpsonRule(Eval& eval, RayState<Real>& s, Real a, Real b,
                         const JitteredGrid<Real>& grid, Real tol, Real minStep, Real length) {
  struct Panel {
    Real a, b;
    MediumSample<Real> sa, sm, sb;
  };
  if (!eval.canAfford(1)) return finishGracefully(eval, s, a, b);
  MediumSample<Real> start = eval(a);
  std::vector<Panel> stack;
  Real t = a;
  while (t < b) {
    const Real tEnd = grid.next(t, b);
    if (!eval.canAfford(2)) return finishGracefully(eval, s, t, b);
    const MediumSample<Real> mid = eval(t + (tEnd - t) / 2);
    const MediumSample<Real> end = eval(tEnd);
    stack.push_back({t, tEnd, start, mid, end});
    while (!stack.empty()) {
      const Panel p = stack.back();
      stack.pop_back();
      const Real h = p.b - p.a;
      const SimpsonPanel<Real> sp = simpsonPanel(p.sa, p.sm, p.sb, h);
      const Real err = panelError(s, sp.q - sp.qTrap, sp.tau - sp.tauTrap);
      const bool broke = !eval.canAfford(2);
      // Both nested rules miss a boundary layer thinner than the panel and would agree on
      // the wrong answer: an optically thick panel (tau > 2) is split regardless.
      const bool thick = sp.tau.maxComponent() > Real(2);
      if (thick && !broke && h / 2 >= minStep) ++eval.counts().stabilityEvents;
      if ((err <= tol * h / length && !thick) || h / 2 < minStep || broke) {
        eval.counts().capped =
            eval.counts().capped || (broke && !eval.opaque() && err > tol * h / length);
        applyPanel(s, sp.q, sp.tau);
        ++eval.counts().steps;
        continue;
      }
      ++eval.counts().rejectedSteps;
      const Real m = p.a + h / 2;
      const MediumSample<Real> left = eval(p.a + h / 4);
      const MediumSample<Real> right = eval(m + h / 4);
      stack.push_back({m, p.b, p.sm, right, p.sb});
      stack.push_back({p.a, m, p.sa, left, p.sm});
    }
    start = end;
    t = tEnd;
  }
}

// Adaptive G7-K15 with recursive halving (all 15 samples of a rejected panel are dropped,
// as Munoz 2014 describes). The accepted value is K15's; the error estimate |K15 - G7|.
template <class Real, class Eval>
void gaussKronrodRule(Eval& eval, RayState<Real>& s, Real a, Real b, const JitteredGrid<Real>& grid,
                      Real tol, Real minStep, Real length) {
  const GaussKronrod15& gk = gaussKronrod15();
  std::vector<std::pair<Real, Real>> stack;
  Real t = a;
  while (t < b) {
    const Real tEnd = grid.next(t, b);
    stack.push_back({t, tEnd});
    while (!stack.empty()) {
      const auto [pa, pb] = stack.back();
      stack.pop_back();
      if (!eval.canAfford(15)) return finishGracefully(eval, s, pa, b);
      const Real half = (pb - pa) / 2;
      std::array<MediumSample<Real>, 15> x;
      for (int i = 0; i < 15; ++i)
        x[i] = eval(pa + half * (Real(1) + static_cast<Real>(gk.nodes[i])));
      Channels<Real> tauK(Real(0)), tauG(Real(0)), qK(Real(0)), qG(Real(0));
      for (int i = 0; i < 15; ++i) {
        tauK += x[i].sigmaT * static_cast<Real>(half * gk.kronrodWeights[i]);
        tauG += x[i].sigmaT * static_cast<Real>(half * gk.gaussWeights[i]);
      }
      for (int i = 0; i < 15; ++i) {
        Channels<Real> tauI(Real(0));
        for (int j = 0; j < 15; ++j)
          tauI += x[j].sigmaT * static_cast<Real>(half * gk.partial[i][j]);
        for (std::size_t c = 0; c < 3; ++c) {
          const Real ti = x[i].source[c] * std::exp(-std::clamp(tauI[c], Real(0), tauK[c]));
          qK[c] += ti * static_cast<Real>(half * gk.kronrodWeights[i]);
          qG[c] += ti * static_cast<Real>(half * gk.gaussWeights[i]);
        }
      }
      const Real err = panelError(s, qK - qG, tauK - tauG);
      // As in adaptive Simpson: an optically thick panel fools both rules alike; split it.
      const bool thick = tauK.maxComponent() > Real(4);
      if (thick && half >= minStep) ++eval.counts().stabilityEvents;
      if ((err <= tol * (pb - pa) / length && !thick) || half < minStep) {
        applyPanel(s, qK, tauK);
        ++eval.counts().steps;
        continue;
      }
      ++eval.counts().rejectedSteps;
      stack.push_back({pa + half, pb});
      stack.push_back({pa, pa + half});
    }
    t = tEnd;
  }
}

// Stratified ("jittered") Monte Carlo: one uniform sample per stratum of length ~step.
template <class Real, class Eval>
void monteCarloRule(Eval& eval, RayState<Real>& s, Real a, Real b, Real step, Rng& rng) {
  const auto n = static_cast<uint64_t>(std::max(Real(1), std::ceil((b - a) / step - Real(1e-9))));
  if (!eval.canAfford(n + 2)) return finishGracefully(eval, s, a, b);
  const Real hs = (b - a) / static_cast<Real>(n);
  MediumSample<Real> prev = eval(a);
  Real tPrev = a;
  Channels<Real> tau(Real(0)), q(Real(0));
  for (uint64_t i = 0; i < n; ++i) {
    const Real ti = a + (static_cast<Real>(i) + static_cast<Real>(rng.uniformDouble())) * hs;
    const MediumSample<Real> x = eval(ti);
    tau += (prev.sigmaT + x.sigmaT) * ((ti - tPrev) / 2);
    for (std::size_t c = 0; c < 3; ++c) q[c] += hs * x.source[c] * std::exp(-tau[c]);
    prev = x;
    tPrev = ti;
  }
  const MediumSample<Real> end = eval(b);
  tau += (prev.sigmaT + end.sigmaT) * ((b - tPrev) / 2);
  applyPanel(s, q, tau);
  eval.counts().steps += n;
}

}  // namespace lvox::rte
