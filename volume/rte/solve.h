#pragma once
// The RTE along one ray segment [t0, t1] (t measured from the camera), per channel:
//   L = int_t0^t1 T(t0, t) J(t) dt + T(t0, t1) Lbg,   T = exp(-int sigma_t).
//
// Formulation: every IVP method integrates the camera-outward system (oracles.md 2)
//   T' = -sigma_t T,  Q' = T J,  T(t0) = 1, Q(t0) = 0,  answer = Q(t1) + T(t1) Lbg,
// rather than the backward dL/du = -sigma_t L + J of the papers. Both are the same linear
// ODE and every method keeps its order on either. The outward form is chosen because it
// marches in the direction rays are traced (the renderer can stop once T is negligible and
// needs no Lbg up front: T and Q are returned and composited once), the transmittance of a
// shadow ray is the same solve with J = 0, and y' = -sigma y is literally the T equation,
// so R(z)^N tests apply to the transmittance unchanged. T is kept with a per-channel
// exponent (RayState) so it never underflows in float.
//
// One non-virtual dispatch per segment: solve() switches on the Method once and then runs a
// driver that is fully inlined on the Problem type.
#include <cmath>
#include <string>
#include <vector>

#include "src/core/error.h"
#include "src/core/rng.h"
#include "volume/rte/adaptive_rk.h"
#include "volume/rte/change_of_variable.h"
#include "volume/rte/fixed_step.h"
#include "volume/rte/method.h"
#include "volume/rte/problem.h"
#include "volume/rte/quadrature.h"
#include "volume/rte/settings.h"
#include "volume/rte/state.h"
#include "volume/rte/tableaus.h"

namespace lvox::rte {

// Throws InputError("volume_integrator", field, ...) for settings no solver can honour.
template <class Real>
void validateSettings(const SolveSettings<Real>& s) {
  auto fail = [](const std::string& field, const std::string& what) {
    throw InputError("volume_integrator", field, what);
  };
  if (!(s.step > Real(0)) || !std::isfinite(s.step)) fail("step", "must be finite and > 0");
  if (!(s.tolerance > Real(0)) || !std::isfinite(s.tolerance))
    fail("tolerance", "must be finite and > 0");
  if (!(s.minStep >= Real(0)) || !std::isfinite(s.minStep)) fail("min_step", "must be >= 0");
  if (!(s.maxStep > Real(0)) || s.maxStep < s.minStep)
    fail("max_step", "must be >= min_step and > 0");
  if (!(s.jitter >= Real(0) && s.jitter < Real(1))) fail("jitter", "must be in [0, 1)");
  if (s.maxEvaluations < 1) fail("max_evaluations", "must be >= 1");
  for (std::size_t i = 0; i < s.breakpoints.size(); ++i) {
    if (!std::isfinite(s.breakpoints[i])) fail("breakpoints", "must be finite");
    if (i > 0 && s.breakpoints[i] < s.breakpoints[i - 1]) fail("breakpoints", "must be sorted");
  }
}

// Analytic transmittance of a homogeneous stretch of length d: exp(-sigma_t d).
template <class Real>
Channels<Real> homogeneousTransmittance(const Channels<Real>& sigmaT, Real d) {
  return {std::exp(-sigmaT[0] * d), std::exp(-sigmaT[1] * d), std::exp(-sigmaT[2] * d)};
}

namespace detail {

template <class Real, class Eval, class Observer>
void runMethod(Method method, Eval& ev, RayState<Real>& state, Real a, Real b,
               const SolveSettings<Real>& set, Observer observer) {
  const JitteredGrid<Real> grid{a, set.step, set.jitter};
  auto pieces = [&](auto&& f) {
    forEachPiece(a, b, set.breakpoints, [&](Real pa, Real pb) {
      ev.setPiece(pa, pb, pa != a, pb != b);
      f(pa, pb);
    });
  };
  auto fixedRk = [&](const auto& tab) {
    const Real stability = static_cast<Real>(stepLimit(method));
    RkStepper<Real, std::decay_t<decltype(tab)>::kStages> st(
        tab, std::min(stability, std::max(set.depthPerStep, Real(1e-3))));
    FixedStepDriver<Real, decltype(st), Eval> d(st, ev, state, set.minStep, stability);
    pieces([&](Real pa, Real pb) { d.run(pa, pb, grid); });
  };
  auto fixedOther = [&](auto stepper) {
    FixedStepDriver<Real, decltype(stepper), Eval> d(stepper, ev, state, set.minStep);
    pieces([&](Real pa, Real pb) { d.run(pa, pb, grid); });
  };
  auto adaptive = [&](const auto& tab) {
    AdaptiveRkDriver<Real, std::decay_t<decltype(tab)>::kStages, Eval, Observer> d(tab, ev, state,
                                                                                   set, observer);
    pieces([&](Real pa, Real pb) { d.run(pa, pb); });
  };
  const Real length = b - a;
  switch (method) {
    case Method::kEuler:
      return fixedRk(kEulerTableau);
    case Method::kRk2:
      return fixedRk(kMidpointTableau);
    case Method::kRk4:
      return fixedRk(kRk4Tableau);
    case Method::kAb4:
      return fixedOther(Ab4Stepper<Real>());
    case Method::kBackwardEuler:
      return fixedOther(BackwardEulerStepper<Real>());
    case Method::kTrapezoid:
      return fixedOther(TrapezoidStepper<Real>());
    case Method::kTrapezoidPc:
      return fixedOther(TrapezoidPcStepper<Real>(set.tolerance));
    case Method::kRk12:
      return adaptive(kHeunEulerTableau);
    case Method::kBs23:
      return adaptive(kBs23Tableau);
    case Method::kRkf45:
      return adaptive(kRkf45Tableau);
    case Method::kCashKarp:
      return adaptive(kCashKarpTableau);
    case Method::kDopri5:
      return adaptive(kDopri5Tableau);
    case Method::kVerner56:
      return adaptive(kVerner56Tableau);
    case Method::kRectangle:
      return pieces([&](Real pa, Real pb) { rectangleRule(ev, state, pa, pb, grid); });
    case Method::kSimpson:
      return fixedOther(SimpsonStepper<Real>());
    case Method::kAdaptiveSimpson:
      return pieces([&](Real pa, Real pb) {
        adaptiveSimpsonRule(ev, state, pa, pb, grid, set.tolerance, set.minStep, length);
      });
    case Method::kGaussKronrod:
      return pieces([&](Real pa, Real pb) {
        gaussKronrodRule(ev, state, pa, pb, grid, set.tolerance, set.minStep, length);
      });
    case Method::kMonteCarlo: {
      Rng rng(set.seed, set.stream);
      return pieces([&](Real pa, Real pb) { monteCarloRule(ev, state, pa, pb, set.step, rng); });
    }
  }
}

template <class Real, class Problem, class Observer>
SolveResult<Real> solveOn(Method method, const Problem& problem, Real a, Real b,
                          const Channels<Real>& background, const SolveSettings<Real>& set,
                          Observer observer) {
  SolveResult<Real> out;
  RayState<Real> state;
  Evaluator<Real, Problem> ev(problem, out.counts, set.maxEvaluations);
  if (set.opaqueDepth < std::numeric_limits<Real>::infinity())
    ev.stopWhenOpaque(state, set.opaqueDepth);
  runMethod(method, ev, state, a, b, set, observer);
  out.transmittance = state.transmittance();
  out.opticalDepth = state.opticalDepth();
  out.radiance = state.Q + out.transmittance * background;
  for (std::size_t c = 0; c < 3; ++c)
    if (!(out.radiance[c] >= Real(0))) out.radiance[c] = Real(0);
  return out;
}

}  // namespace detail

// Solves one segment. `settings.breakpoints` outside (t0, t1) are ignored. With a change
// of variable, the fixed step becomes (s1 - s0) / ceil((t1 - t0) / step) in the new
// variable (the same number of steps), and min/max step scale by (s1 - s0) / (t1 - t0).
// `observer(t, h, before, after)` sees every accepted step of the adaptive pairs (tests).
template <class Real, class Problem, class Observer = NoStepObserver>
requires RteProblem<Problem, Real> SolveResult<Real> solve(Method method, const Problem& problem,
                                                           Real t0, Real t1,
                                                           const Channels<Real>& background,
                                                           const SolveSettings<Real>& settings,
                                                           Observer observer = {}) {
  validateSettings(settings);
  if (!std::isfinite(t0) || !std::isfinite(t1) || t1 < t0)
    throw InputError("volume_integrator", "segment", "needs finite t0 <= t1");
  if (t1 == t0) {
    SolveResult<Real> out;
    out.radiance = background;
    out.transmittance = Channels<Real>(Real(1));
    return out;
  }
  const VariableChange<Real> map = VariableChange<Real>::make(
      settings.sampling, t0, settings.sigmaRef, settings.delta, settings.h);
  if (map.kind == Sampling::kNone)
    return detail::solveOn(method, problem, t0, t1, background, settings, observer);
  const Real s0 = map.toS(t0), s1 = map.toS(t1);
  const Real ratio = (s1 - s0) / (t1 - t0);
  SolveSettings<Real> mapped = settings;
  mapped.step = (s1 - s0) / std::max(Real(1), std::ceil((t1 - t0) / settings.step - Real(1e-9)));
  mapped.minStep = settings.minStep * ratio;
  mapped.maxStep = settings.maxStep * ratio;
  for (Real& bp : mapped.breakpoints) bp = map.toS(std::clamp(bp, t0, t1));
  const MappedProblem<Problem, Real> wrapped{problem, map};
  return detail::solveOn(method, wrapped, s0, s1, background, mapped, observer);
}

// Transmittance only (shadow rays): the same method on T' = -sigma_t T.
template <class Real, class Problem>
requires RteProblem<Problem, Real> SolveResult<Real> solveTransmittance(
    Method method, const Problem& problem, Real t0, Real t1, const SolveSettings<Real>& settings) {
  const WithoutSource<Problem> dark{problem};
  return solve(method, dark, t0, t1, Channels<Real>(Real(0)), settings);
}

}  // namespace lvox::rte
