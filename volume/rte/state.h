#pragma once
// The state every method advances, and the pieces all drivers share: counted medium
// evaluations, the jittered fixed-step grid, and the exact constant-coefficient step used
// when the evaluation budget runs out or an explicit step would need a sub-minStep step.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "volume/rte/channels.h"
#include "volume/rte/problem.h"
#include "volume/rte/settings.h"

namespace lvox::rte {

// Camera-outward form: T' = -sigma T, Q' = T J. T is stored as T * exp(tauShift): once a
// channel's T would fall below kRescaleBelow the factor moves into tauShift, so float never
// underflows to 0 and the optical depth stays known (oracles.md 2.1, Mitsuba PR #1959).
template <class Real>
struct RayState {
  static constexpr Real kRescaleBelow = Real(1e-20);

  Channels<Real> T{Real(1)};
  Channels<Real> Q{Real(0)};
  Channels<Real> tauShift{Real(0)};
  Channels<Real> scale{Real(1)};  // exp(-tauShift): multiplies the source's contribution

  // Clamps rounding-level negatives and NaN (never produced by a stable step) and rescales.
  void settle() {
    for (std::size_t c = 0; c < 3; ++c) {
      if (!(T[c] > Real(0))) T[c] = Real(0);
      if (!(Q[c] > Real(0))) Q[c] = Real(0);  // also catches NaN
      Q[c] = std::min(Q[c], std::numeric_limits<Real>::max());
      if (T[c] > Real(0) && T[c] < kRescaleBelow) {
        tauShift[c] -= std::log(T[c]);
        T[c] = Real(1);
        scale[c] = std::exp(-tauShift[c]);
      }
    }
  }
  Channels<Real> transmittance() const { return T * scale; }
  Channels<Real> opticalDepth() const {
    Channels<Real> tau;
    for (std::size_t c = 0; c < 3; ++c)
      tau[c] =
          T[c] > Real(0) ? tauShift[c] - std::log(T[c]) : std::numeric_limits<Real>::infinity();
    return tau;
  }
};

// Counts evaluations and sanitises them: sigma < 0 would turn decay into growth (oracles.md
// bad input 7) and NaN must never reach the state.
template <class Real, class Problem>
class Evaluator {
 public:
  Evaluator(const Problem& problem, SolveCounts& counts, uint32_t maxEvaluations)
      : problem_(problem), counts_(counts), max_(maxEvaluations) {}

  // Evaluations inside a piece that ends at a breakpoint are nudged off it, so each side
  // sees its own one-sided value of the jump (an exact-node value would cost order 1).
  void setPiece(Real a, Real b, bool breakAtA, bool breakAtB) {
    const Real eps = Real(16) * std::numeric_limits<Real>::epsilon() *
                     std::max({Real(1), std::abs(a), std::abs(b)});
    lo_ = breakAtA ? a + eps : -std::numeric_limits<Real>::infinity();
    hi_ = breakAtB ? b - eps : std::numeric_limits<Real>::infinity();
  }

  MediumSample<Real> operator()(Real t) {
    ++counts_.mediumEvals;
    MediumSample<Real> s = problem_.eval(std::clamp(t, lo_, hi_));
    for (std::size_t c = 0; c < 3; ++c) {
      if (!(s.sigmaT[c] >= Real(0))) s.sigmaT[c] = Real(0);
      if (!(s.source[c] >= Real(0))) s.source[c] = Real(0);
      s.sigmaT[c] = std::min(s.sigmaT[c], std::numeric_limits<Real>::max());
      s.source[c] = std::min(s.source[c], std::numeric_limits<Real>::max());
    }
    last_ = s;
    return s;
  }
  // The most recent sample (transparent and dark before the first): what a capped solve
  // finishes with.
  const MediumSample<Real>& last() const { return last_; }
  // From now on, stop (canAfford says no) once every channel of `state` is below
  // exp(-opaqueDepth).
  void stopWhenOpaque(const RayState<Real>& state, Real opaqueDepth) {
    state_ = &state;
    opaqueT_ = std::exp(-opaqueDepth);
  }
  bool opaque() const {
    if (!state_ || !(opaqueT_ > Real(0))) return false;
    const Channels<Real> t = state_->transmittance();
    return t[0] < opaqueT_ && t[1] < opaqueT_ && t[2] < opaqueT_;
  }
  bool canAfford(uint64_t n) const { return counts_.mediumEvals + n <= max_ && !opaque(); }
  uint64_t remaining() const { return max_ > counts_.mediumEvals ? max_ - counts_.mediumEvals : 0; }
  SolveCounts& counts() { return counts_; }

 private:
  const Problem& problem_;
  SolveCounts& counts_;
  uint64_t max_;
  const RayState<Real>* state_ = nullptr;
  Real opaqueT_ = Real(0);
  Real lo_ = -std::numeric_limits<Real>::infinity();
  Real hi_ = std::numeric_limits<Real>::infinity();
  MediumSample<Real> last_{};
};

// (1 - exp(-x)) / x, accurate for small x and for x -> infinity.
template <class Real>
Real oneMinusExpOver(Real x) {
  if (x < Real(1e-4)) return Real(1) - x / Real(2) + x * x / Real(6);
  return -std::expm1(-x) / x;
}

// Exact step for sigma and J constant over [t, t + h] at the averages of the two samples:
// unconditionally positive, first order. Used for graceful finishes and stiff fallbacks.
template <class Real>
void constantCoefficientStep(RayState<Real>& s, const MediumSample<Real>& a,
                             const MediumSample<Real>& b, Real h) {
  for (std::size_t c = 0; c < 3; ++c) {
    const Real sigma = Real(0.5) * (a.sigmaT[c] + b.sigmaT[c]);
    const Real j = Real(0.5) * (a.source[c] + b.source[c]);
    const Real x = sigma * h;
    s.Q[c] += s.scale[c] * s.T[c] * j * h * oneMinusExpOver(x);
    s.T[c] *= std::exp(-x);
  }
  s.settle();
}

// The evaluation budget is spent: cover [t, b] with one exact constant-coefficient step
// from the last sample (and one at b if a single evaluation is left). Never negative.
template <class Real, class Eval>
void finishGracefully(Eval& eval, RayState<Real>& s, Real t, Real b) {
  if (!eval.opaque()) eval.counts().capped = true;  // an opaque stop loses nothing visible
  if (b <= t) return;
  const MediumSample<Real> a = eval.last();
  const MediumSample<Real> end = eval.canAfford(1) ? eval(b) : a;
  constantCoefficientStep(s, a, end, b - t);
  ++eval.counts().steps;
}

// Nodes of the fixed-step grid t0 + (jitter + k) h, restricted to (a, b); steps end at b.
template <class Real>
struct JitteredGrid {
  Real origin;
  Real h;
  Real jitter;

  Real next(Real t, Real b) const {
    const Real slack = h * Real(1e-9);
    Real k = std::floor((t - origin) / h - jitter);
    Real node = origin + (jitter + k) * h;
    while (node <= t + slack) {
      k += Real(1);
      node = origin + (jitter + k) * h;
    }
    return node >= b - slack ? b : node;
  }
};

// Splits [t0, t1] at the breakpoints strictly inside it and calls f(a, b) per piece.
template <class Real, class F>
void forEachPiece(Real t0, Real t1, const std::vector<Real>& breakpoints, F&& f) {
  Real a = t0;
  for (Real bp : breakpoints) {
    if (bp <= a || bp >= t1) continue;
    f(a, bp);
    a = bp;
  }
  f(a, t1);
}

}  // namespace lvox::rte
