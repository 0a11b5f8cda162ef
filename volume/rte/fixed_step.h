#pragma once
// Fixed-step IVP solvers on the jittered grid: explicit RK (any tableau), AB4, backward
// Euler, trapezoid (closed form) and the fixed-point trapezoid of Munoz 2012. One driver
// handles the grid, the evaluation budget and the stability/positivity limit; a stepper
// only knows its own formula.
#include <cmath>
#include <cstdint>

#include "volume/rte/rk_step.h"
#include "volume/rte/state.h"

namespace lvox::rte {

template <class Real>
struct StepAttempt {
  bool stable = true;  // false: sigma*h exceeded `limit`, nothing was committed
  Real sigmaMax = Real(0);
  Real limit = Real(0);
  bool hasEnd = false;  // `end` is the sample at the step's end (the next start)
  MediumSample<Real> end{};
};

template <class Real, std::size_t S>
class RkStepper {
 public:
  RkStepper(const ButcherTableau<S>& tab, Real limit) : tab_(tab), limit_(limit) {}
  uint64_t evalsPerStep() const { return newEvaluationsPerStep(tab_); }
  void restart() {}

  template <class Eval>
  StepAttempt<Real> attempt(RayState<Real>& s, Real t, Real tEnd, const MediumSample<Real>& start,
                            Eval& eval) {
    const Real h = tEnd - t;
    StepAttempt<Real> out{true, start.sigmaT.maxComponent(), limit_};
    if (out.sigmaMax * h > limit_ * Real(1.000001)) return out.stable = false, out;
    StageSamples<Real, S> samples;
    evaluateStages(tab_, eval, t, tEnd, start, samples);
    out.sigmaMax = maxSigma(samples);
    if (out.sigmaMax * h > limit_ * Real(1.000001)) return out.stable = false, out;
    const RkIncrement<Real> inc = rkCombine(tab_, s, samples, h);
    s.T = inc.T;
    s.Q = inc.Q;
    s.settle();
    const std::size_t e = endStage(tab_);
    if (e < S) out.hasEnd = true, out.end = samples[e];
    return out;
  }

 private:
  const ButcherTableau<S>& tab_;
  Real limit_;
};

// Backward Euler, solved exactly (the RTE is linear): T1 = T/(1 + h sigma1), Q1 = Q + h J1 T1.
// L-stable and positive for every h.
template <class Real>
void backwardEulerStep(RayState<Real>& s, const MediumSample<Real>& end, Real h) {
  for (std::size_t c = 0; c < 3; ++c) {
    s.T[c] /= Real(1) + h * end.sigmaT[c];
    s.Q[c] += h * end.source[c] * s.scale[c] * s.T[c];
  }
  s.settle();
}

template <class Real>
class BackwardEulerStepper {
 public:
  uint64_t evalsPerStep() const { return 1; }
  void restart() {}
  template <class Eval>
  StepAttempt<Real> attempt(RayState<Real>& s, Real t, Real tEnd, const MediumSample<Real>&,
                            Eval& eval) {
    StepAttempt<Real> out;
    out.hasEnd = true;
    out.end = eval(tEnd);
    backwardEulerStep(s, out.end, tEnd - t);
    return out;
  }
};

// Trapezoid solved exactly: T1 = T (1 - h s0/2)/(1 + h s1/2). A-stable, but R < 0 once
// h sigma0 > 2, so such a step is taken by backward Euler instead (a stability event; no
// step reduction and no extra evaluation).
template <class Real>
class TrapezoidStepper {
 public:
  uint64_t evalsPerStep() const { return 1; }
  void restart() {}
  template <class Eval>
  StepAttempt<Real> attempt(RayState<Real>& s, Real t, Real tEnd, const MediumSample<Real>& start,
                            Eval& eval) {
    const Real h = tEnd - t;
    StepAttempt<Real> out;
    out.hasEnd = true;
    out.end = eval(tEnd);
    if (start.sigmaT.maxComponent() * h > Real(2.000002)) {
      ++eval.counts().stabilityEvents;
      backwardEulerStep(s, out.end, h);
      return out;
    }
    for (std::size_t c = 0; c < 3; ++c) {
      const Real t1 =
          s.T[c] * (Real(1) - h * start.sigmaT[c] / 2) / (Real(1) + h * out.end.sigmaT[c] / 2);
      s.Q[c] += h / 2 * s.scale[c] * (start.source[c] * s.T[c] + out.end.source[c] * t1);
      s.T[c] = t1;
    }
    s.settle();
    return out;
  }
};

// Trapezoid by Euler predictor + fixed-point corrector iterated to `tol` (Munoz 2012). The
// iteration contracts by h sigma1/2, so it is explicit in disguise: limit h sigma <= 1.
template <class Real>
class TrapezoidPcStepper {
 public:
  explicit TrapezoidPcStepper(Real tol) : tol_(tol) {}
  uint64_t evalsPerStep() const { return 1; }
  void restart() {}
  uint64_t iterations() const { return iterations_; }

  template <class Eval>
  StepAttempt<Real> attempt(RayState<Real>& s, Real t, Real tEnd, const MediumSample<Real>& start,
                            Eval& eval) {
    const Real h = tEnd - t;
    StepAttempt<Real> out{true, start.sigmaT.maxComponent(), Real(1)};
    if (out.sigmaMax * h > out.limit * Real(1.000001)) return out.stable = false, out;
    out.hasEnd = true;
    out.end = eval(tEnd);
    out.sigmaMax = std::max(out.sigmaMax, out.end.sigmaT.maxComponent());
    if (out.sigmaMax * h > out.limit * Real(1.000001)) return out.stable = false, out;
    const Channels<Real> f0 = Channels<Real>(Real(0)) - start.sigmaT * s.T;
    Channels<Real> t1 = s.T + f0 * h;  // Euler predictor
    for (int it = 0; it < kMaxIterations; ++it) {
      ++iterations_;
      const Channels<Real> next = s.T + (f0 - out.end.sigmaT * t1) * (h / 2);
      Real change = Real(0);
      for (std::size_t c = 0; c < 3; ++c)
        change = std::max(change, std::abs(next[c] - t1[c]) / (Real(1) + std::abs(next[c])));
      t1 = next;
      if (change <= tol_) break;
    }
    s.Q += (start.source * s.T + out.end.source * t1) * s.scale * (h / 2);
    s.T = t1;
    s.settle();
    return out;
  }

 private:
  static constexpr int kMaxIterations = 60;
  Real tol_;
  uint64_t iterations_ = 0;
};

// Adams-Bashforth 4 on equal steps, started (and restarted after every breakpoint, every
// step of another length and every stability fallback) with RK4 steps.
template <class Real>
class Ab4Stepper {
 public:
  Ab4Stepper() : rk4_(kRk4Tableau, Real(2)) {}
  uint64_t evalsPerStep() const { return 2; }  // worst case: an RK4 step
  void restart() { count_ = 0; }

  template <class Eval>
  StepAttempt<Real> attempt(RayState<Real>& s, Real t, Real tEnd, const MediumSample<Real>& start,
                            Eval& eval) {
    const Real h = tEnd - t;
    if (count_ > 0 && s.scale.v != scale_.v) count_ = 0;  // T was rescaled: history stale
    const Channels<Real> fT = Channels<Real>(Real(0)) - start.sigmaT * s.T;
    const Channels<Real> fQ = start.source * s.scale * s.T;
    const bool equal = count_ >= 3 && std::abs(h - h_) <= Real(1e-9) * h;
    if (equal && start.sigmaT.maxComponent() * h <= Real(0.2000002)) {
      s.T += (fT * Real(55) - hT_[0] * Real(59) + hT_[1] * Real(37) - hT_[2] * Real(9)) * (h / 24);
      s.Q += (fQ * Real(55) - hQ_[0] * Real(59) + hQ_[1] * Real(37) - hQ_[2] * Real(9)) * (h / 24);
      push(fT, fQ, h);
      s.settle();
      scale_ = s.scale;
      return StepAttempt<Real>{true, start.sigmaT.maxComponent(), Real(0.3)};
    }
    if (equal) ++eval.counts().stabilityEvents;  // AB4 unstable here: RK4 takes the step
    StepAttempt<Real> out = rk4_.attempt(s, t, tEnd, start, eval);
    if (!out.stable) {
      count_ = 0;
      return out;
    }
    if (count_ == 0 || std::abs(h - h_) > Real(1e-9) * h) count_ = 0;
    push(fT, fQ, h);
    scale_ = s.scale;
    return out;
  }

 private:
  void push(const Channels<Real>& fT, const Channels<Real>& fQ, Real h) {
    for (int i = 2; i > 0; --i) hT_[i] = hT_[i - 1], hQ_[i] = hQ_[i - 1];
    hT_[0] = fT;
    hQ_[0] = fQ;
    count_ = std::min(count_ + 1, 3);
    h_ = h;
  }
  RkStepper<Real, 4> rk4_;
  std::array<Channels<Real>, 3> hT_, hQ_;  // f at t_{n-1}, t_{n-2}, t_{n-3}
  int count_ = 0;
  Real h_ = Real(0);
  Channels<Real> scale_{Real(1)};
};

// Walks [a, b] on the grid. A step beyond the stepper's limit is split into
// ceil(sigma h / limit) substeps (one stability event when sigma h is past
// `stabilityLimit`, else an accuracy split); if the substeps would fall below minStep or
// exceed the budget, an exact constant-coefficient step covers it instead.
template <class Real, class Stepper, class Eval>
class FixedStepDriver {
 public:
  FixedStepDriver(Stepper& stepper, Eval& eval, RayState<Real>& state, Real minStep,
                  Real stabilityLimit = Real(0))
      : stepper_(stepper),
        eval_(eval),
        s_(state),
        minStep_(minStep),
        stabilityLimit_(stabilityLimit) {}

  void run(Real a, Real b, const JitteredGrid<Real>& grid) {
    stepper_.restart();
    if (!eval_.canAfford(1)) return finishGracefully(eval_, s_, a, b);
    MediumSample<Real> start = eval_(a);
    Real t = a;
    while (t < b) {
      const Real tEnd = grid.next(t, b);
      if (!eval_.canAfford(stepper_.evalsPerStep() + 1)) return finishGracefully(eval_, s_, t, b);
      const StepAttempt<Real> r = step(t, tEnd, start, 0);
      t = tEnd;
      if (t < b) start = r.hasEnd ? r.end : eval_(t);
    }
  }

 private:
  StepAttempt<Real> step(Real t, Real tEnd, const MediumSample<Real>& start, int depth) {
    StepAttempt<Real> r = stepper_.attempt(s_, t, tEnd, start, eval_);
    if (r.stable) {
      ++eval_.counts().steps;
      return r;
    }
    const Real h = tEnd - t;
    if (r.sigmaMax * h > stabilityLimit_ * Real(1.000001)) ++eval_.counts().stabilityEvents;
    stepper_.restart();
    const Real m = std::ceil(r.sigmaMax * h / (r.limit * Real(1.000001)));
    const Real hs = h / m;
    if (depth >= 2 || hs < minStep_ || m > Real(1e6) ||
        !eval_.canAfford(static_cast<uint64_t>(m) * (stepper_.evalsPerStep() + 1))) {
      StepAttempt<Real> out;
      out.hasEnd = true;
      out.end = eval_.canAfford(1) ? eval_(tEnd) : eval_.last();
      constantCoefficientStep(s_, start, out.end, h);
      ++eval_.counts().steps;
      return out;
    }
    const auto n = static_cast<uint64_t>(m);
    MediumSample<Real> cur = start;
    StepAttempt<Real> last;
    for (uint64_t k = 0; k < n; ++k) {
      const Real a = t + static_cast<Real>(k) * hs;
      const Real e = k + 1 == n ? tEnd : t + static_cast<Real>(k + 1) * hs;
      last = step(a, e, cur, depth + 1);
      if (k + 1 < n) cur = last.hasEnd ? last.end : eval_(e);
    }
    return last;
  }

  Stepper& stepper_;
  Eval& eval_;
  RayState<Real>& s_;
  Real minStep_;
  Real stabilityLimit_;
};

}  // namespace lvox::rte
