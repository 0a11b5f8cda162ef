#pragma once
// Per-segment solver settings and the result every solve returns.
#include <cstdint>
#include <limits>
#include <vector>

#include "volume/rte/channels.h"
#include "volume/rte/method.h"

namespace lvox::rte {

template <class Real>
struct SolveSettings {
  // Fixed-step methods: step length in t (scene units). Adaptive methods: the first trial
  // step (and the initial panel length of the adaptive quadratures).
  Real step = Real(0.1);
  Real tolerance = Real(1e-3);  // adaptive methods; also the trapezoid-pc corrector
  Real minStep = Real(1e-6);    // adaptive step floor (a step at the floor is accepted)
  Real maxStep = std::numeric_limits<Real>::infinity();
  // Start offset of the fixed-step grid in units of `step`, in [0, 1): nodes sit at
  // t0 + (jitter + k) step. The caller draws it per ray against banding (Gonterman 2010).
  Real jitter = Real(0);
  // Sorted t where sigma or the source jump (medium boundaries, shadow edges, voxel faces):
  // no step straddles one and multistep history restarts there (oracles.md 3.3).
  std::vector<Real> breakpoints;
  uint32_t maxEvaluations = 100000;  // per segment; then finish with the last sample
  // Fixed-step Runge-Kutta methods: a step whose sigma_t h exceeds this (at its start or
  // any stage) is split into equal substeps that do not, where it happens: a local
  // accuracy control from the medium itself (auto sets it; RK4's error on exp(-tau) is
  // tau^5 / 120 per step). Splits below the method's stability limit are not counted as
  // stability events. Infinity: only the stability limit splits steps.
  Real depthPerStep = std::numeric_limits<Real>::infinity();
  // Optical depth past which nothing behind is visible: once every channel's T is below
  // exp(-opaqueDepth) the rest of the segment is one constant-coefficient step from the
  // last sample (not counted as capped). Infinity: integrate to the end. The renderer
  // uses 16.2 (T < 1e-7): in a medium thousands of optical depths thick, every shadow
  // ray would otherwise run its full evaluation budget (issue 16: 16 camera rays took
  // 231 M evaluations in smoke at density_scale 1e4).
  Real opaqueDepth = std::numeric_limits<Real>::infinity();
  uint32_t maxRejections = 30;  // consecutive rejections before accepting at minStep
  // Monte Carlo: the sample stream (lvox::Rng(seed, stream)).
  uint64_t seed = 1;
  uint64_t stream = 0;
  // Change of variable and its parameters (oracles.md 2.2 and 2.6): distance sampling uses
  // s = 1 - exp(-sigmaRef (t - t0)); equiangular uses t - delta = h tan(u).
  Sampling sampling = Sampling::kNone;
  Real sigmaRef = Real(1);
  Real delta = Real(0);
  Real h = Real(1);
};

struct SolveCounts {
  uint64_t steps = 0;            // accepted steps (quadrature: accepted panels / samples)
  uint64_t rejectedSteps = 0;    // adaptive rejections (quadrature: split panels)
  uint64_t mediumEvals = 0;      // calls to problem.eval
  uint64_t stabilityEvents = 0;  // steps reduced (or replaced) because sigma_t*h > limit
  bool capped = false;           // hit maxEvaluations; the rest used the last sample

  SolveCounts& operator+=(const SolveCounts& o) {
    steps += o.steps;
    rejectedSteps += o.rejectedSteps;
    mediumEvals += o.mediumEvals;
    stabilityEvents += o.stabilityEvents;
    capped = capped || o.capped;
    return *this;
  }
};

template <class Real>
struct SolveResult {
  Channels<Real> radiance;       // Q(t1) + T(t1) Lbg
  Channels<Real> transmittance;  // T(t0, t1)
  Channels<Real> opticalDepth;   // -ln T, kept finite where T underflows
  SolveCounts counts;
};

}  // namespace lvox::rte
