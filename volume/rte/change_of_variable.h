#pragma once
// Importance sampling as a change of variable usable with every method (Munoz 2014 sec. 5):
// with t = phi(s) the (T, Q) system in s has coefficients sigma(phi(s)) phi'(s) and
// J(phi(s)) phi'(s), so the solvers run unchanged on the wrapped problem.
//   distance:    s = 1 - exp(-sigmaRef (t - t0)),  dt/ds = 1 / (sigmaRef (1 - s))
//   equiangular: t - delta = h tan(s),              dt/ds = h (1 + tan^2 s)   (oracles 2.2)
// A degenerate parameter (sigmaRef <= 0, h <= 0: the ray through the light) falls back to
// the identity map rather than failing mid-render.
#include <cmath>

#include "volume/rte/channels.h"
#include "volume/rte/method.h"

namespace lvox::rte {

template <class Real>
struct VariableChange {
  Sampling kind = Sampling::kNone;
  Real t0 = Real(0), sigmaRef = Real(1), delta = Real(0), h = Real(1);

  static VariableChange make(Sampling kind, Real t0, Real sigmaRef, Real delta, Real h) {
    const bool ok =
        (kind == Sampling::kDistance && sigmaRef > Real(0) && std::isfinite(sigmaRef)) ||
        (kind == Sampling::kEquiangular && h > Real(0) && std::isfinite(h) && std::isfinite(delta));
    return ok ? VariableChange{kind, t0, sigmaRef, delta, h} : VariableChange{Sampling::kNone, t0};
  }

  Real toS(Real t) const {
    switch (kind) {
      case Sampling::kDistance:
        return -std::expm1(-sigmaRef * (t - t0));
      case Sampling::kEquiangular:
        return std::atan((t - delta) / h);
      default:
        return t;
    }
  }
  Real toT(Real s) const {
    switch (kind) {
      case Sampling::kDistance:
        return t0 - std::log1p(-s) / sigmaRef;
      case Sampling::kEquiangular:
        return delta + h * std::tan(s);
      default:
        return s;
    }
  }
  Real dtds(Real s) const {
    switch (kind) {
      case Sampling::kDistance:
        return Real(1) / (sigmaRef * (Real(1) - s));
      case Sampling::kEquiangular: {
        const Real tn = std::tan(s);
        return h * (Real(1) + tn * tn);
      }
      default:
        return Real(1);
    }
  }
};

template <class Problem, class Real>
struct MappedProblem {
  const Problem& inner;
  VariableChange<Real> map;
  MediumSample<Real> eval(Real s) const {
    MediumSample<Real> m = inner.eval(map.toT(s));
    const Real j = map.dtds(s);
    m.sigmaT = m.sigmaT * j;
    m.source = m.source * j;
    return m;
  }
};

}  // namespace lvox::rte
