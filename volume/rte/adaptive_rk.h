#pragma once
// Embedded Runge-Kutta pairs with error-per-step control (Hairer, Norsett & Wanner I,
// II.4). The error of a step is max over the six components (T and Q per channel) of
// |err| / (tol (1 + max(|y_n|, |y_n+1|))): relative for large values, absolute below 1.
// Step size: PI controller h *= 0.9 err^(-0.7/k) errPrev^(0.4/k), k = 1 + min order of the
// pair, clamped to [0.2, 5] (no growth right after a rejection). A step that reaches
// minStep or exceeds maxRejections consecutive rejections is accepted as it is.
#include <algorithm>
#include <cmath>

#include "volume/rte/rk_step.h"
#include "volume/rte/state.h"

namespace lvox::rte {

// Receives every accepted step: (t, h, state before, state after). The default ignores it.
struct NoStepObserver {
  template <class Real>
  void operator()(Real, Real, const RayState<Real>&, const RayState<Real>&) const {}
};

template <class Real>
Real embeddedErrorNorm(const RayState<Real>& before, const RkIncrement<Real>& inc, Real tol) {
  Real err = Real(0);
  for (std::size_t c = 0; c < 3; ++c) {
    const Real scT = tol * (Real(1) + std::max(std::abs(before.T[c]), std::abs(inc.T[c])));
    const Real scQ = tol * (Real(1) + std::max(std::abs(before.Q[c]), std::abs(inc.Q[c])));
    err = std::max({err, std::abs(inc.errT[c]) / scT, std::abs(inc.errQ[c]) / scQ});
  }
  return std::isfinite(err) ? err : std::numeric_limits<Real>::max();
}

template <class Real, std::size_t S, class Eval, class Observer = NoStepObserver>
class AdaptiveRkDriver {
 public:
  AdaptiveRkDriver(const ButcherTableau<S>& tab, Eval& eval, RayState<Real>& state,
                   const SolveSettings<Real>& settings, Observer observer = {})
      : tab_(tab),
        eval_(eval),
        s_(state),
        set_(settings),
        observer_(observer),
        h_(std::clamp(settings.step, settings.minStep, settings.maxStep)) {}

  void run(Real a, Real b) {
    if (!eval_.canAfford(1)) return finishGracefully(eval_, s_, a, b);
    MediumSample<Real> start = eval_(a);
    const Real k = static_cast<Real>(std::min(tab_.order, tab_.errorOrder) + 1);
    Real errPrev = Real(1);
    uint32_t rejections = 0;
    Real t = a;
    while (t < b) {
      Real h = std::min(h_, b - t);
      // Do not leave a sliver: stretch the step to b if less than 1% of it would remain.
      if (b - (t + h) < Real(0.01) * h) h = b - t;
      const bool clipped = h < h_ * Real(0.99);  // cut by the piece end: not the controller's h
      const Real tEnd = h == b - t ? b : t + h;
      if (!eval_.canAfford(newEvaluationsPerStep(tab_) + 1))
        return finishGracefully(eval_, s_, t, b);
      StageSamples<Real, S> samples;
      evaluateStages(tab_, eval_, t, tEnd, start, samples);
      const RkIncrement<Real> inc = rkCombine(tab_, s_, samples, h);
      const Real err = embeddedErrorNorm(s_, inc, set_.tolerance);
      const bool atFloor = h <= set_.minStep * Real(1.000001);
      if (err > Real(1) && !atFloor && rejections < set_.maxRejections) {
        ++eval_.counts().rejectedSteps;
        ++rejections;
        h_ = std::max(set_.minStep, h * std::max(Real(0.2), Real(0.9) * std::pow(err, -1 / k)));
        continue;
      }
      const RayState<Real> before = s_;
      s_.T = inc.T;
      s_.Q = inc.Q;
      s_.settle();
      observer_(t, h, before, s_);
      ++eval_.counts().steps;
      Real factor = Real(0.9) * std::pow(std::max(err, Real(1e-10)), Real(-0.7) / k) *
                    std::pow(errPrev, Real(0.4) / k);
      factor = std::clamp(factor, Real(0.2), rejections > 0 ? Real(1) : Real(5));
      errPrev = std::max(err, Real(1e-4));
      rejections = 0;
      if (!clipped) h_ = std::clamp(h * factor, set_.minStep, set_.maxStep);
      t = tEnd;
      if (t < b) {
        const std::size_t e = endStage(tab_);
        start = e < S ? samples[e] : eval_(t);
      }
    }
  }

 private:
  const ButcherTableau<S>& tab_;
  Eval& eval_;
  RayState<Real>& s_;
  const SolveSettings<Real>& set_;
  Observer observer_;
  Real h_;
};

}  // namespace lvox::rte
