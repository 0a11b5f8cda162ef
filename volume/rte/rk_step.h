#pragma once
// One explicit Runge-Kutta step of the linear (T, Q) system for any tableau. Stages at the
// same abscissa share one medium evaluation (the RHS is linear in the state, so only the
// sample is needed, not f): RK4 costs 2 new evaluations, DOPRI5 5, FSAL comes for free
// because the c = 1 sample becomes the next step's start sample.
#include <array>
#include <cstddef>

#include "volume/rte/state.h"
#include "volume/rte/tableaus.h"

namespace lvox::rte {

template <class Real, std::size_t S>
using StageSamples = std::array<MediumSample<Real>, S>;

// Number of distinct abscissae other than c = 0: the new evaluations per step.
template <std::size_t S>
constexpr std::size_t newEvaluationsPerStep(const ButcherTableau<S>& tab) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < S; ++i) {
    bool seen = tab.c[i] == 0.0;
    for (std::size_t j = 0; j < i; ++j) seen = seen || tab.c[j] == tab.c[i];
    n += seen ? 0 : 1;
  }
  return n;
}

// Index of a stage at c = 1 (its sample is the next start sample), or S if none.
template <std::size_t S>
constexpr std::size_t endStage(const ButcherTableau<S>& tab) {
  for (std::size_t i = 0; i < S; ++i)
    if (tab.c[i] == 1.0) return i;
  return S;
}

// Fills the stage samples of the step [t, tEnd]; stage 0 (c = 0) uses `start`.
template <class Real, std::size_t S, class Eval>
void evaluateStages(const ButcherTableau<S>& tab, Eval& eval, Real t, Real tEnd,
                    const MediumSample<Real>& start, StageSamples<Real, S>& samples) {
  const Real h = tEnd - t;
  for (std::size_t i = 0; i < S; ++i) {
    if (tab.c[i] == 0.0) {
      samples[i] = start;
      continue;
    }
    std::size_t j = 0;
    while (j < i && tab.c[j] != tab.c[i]) ++j;
    if (j < i) {
      samples[i] = samples[j];
    } else {
      samples[i] = eval(tab.c[i] == 1.0 ? tEnd : t + static_cast<Real>(tab.c[i]) * h);
    }
  }
}

template <class Real>
struct RkIncrement {
  Channels<Real> T, Q;        // the propagated solution at the end of the step
  Channels<Real> errT, errQ;  // h (b - bHat) k: the embedded error estimate
};

template <class Real, std::size_t S>
RkIncrement<Real> rkCombine(const ButcherTableau<S>& tab, const RayState<Real>& s,
                            const StageSamples<Real, S>& samples, Real h) {
  std::array<Channels<Real>, S> kT, kQ;
  RkIncrement<Real> out{s.T, s.Q, Channels<Real>(Real(0)), Channels<Real>(Real(0))};
  for (std::size_t i = 0; i < S; ++i) {
    Channels<Real> y = s.T;
    for (std::size_t j = 0; j < i; ++j)
      if (tab.a[i][j] != 0.0) y += kT[j] * (h * static_cast<Real>(tab.a[i][j]));
    kT[i] = Channels<Real>(Real(0)) - samples[i].sigmaT * y;
    kQ[i] = samples[i].source * s.scale * y;
    const Real b = h * static_cast<Real>(tab.b[i]);
    const Real e = h * static_cast<Real>(tab.b[i] - tab.bHat[i]);
    out.T += kT[i] * b;
    out.Q += kQ[i] * b;
    out.errT += kT[i] * e;
    out.errQ += kQ[i] * e;
  }
  return out;
}

template <class Real, std::size_t S>
Real maxSigma(const StageSamples<Real, S>& samples) {
  Real m = Real(0);
  for (const auto& s : samples) m = std::max(m, s.sigmaT.maxComponent());
  return m;
}

}  // namespace lvox::rte
