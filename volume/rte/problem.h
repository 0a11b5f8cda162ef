#pragma once
// What a solver integrates: any type with `MediumSample<Real> eval(Real t) const`, where t
// is the distance from the camera along the ray. Every call is one medium evaluation (the
// cost unit of design.md); the solvers count them and never call eval twice for one t
// within a step.
#include <concepts>

#include "volume/rte/channels.h"

namespace lvox::rte {

template <class P, class Real>
concept RteProblem = requires(const P& problem, Real t) {
  { problem.eval(t) } -> std::convertible_to<MediumSample<Real>>;
};

// The same medium with its source switched off: dQ = 0, so a full solve returns only the
// transmittance. Used for shadow rays, so they run through exactly the same method.
template <class Problem>
struct WithoutSource {
  const Problem& inner;
  template <class Real>
  MediumSample<Real> eval(Real t) const {
    MediumSample<Real> s = inner.eval(t);
    s.source = Channels<Real>(Real(0));
    return s;
  }
};

}  // namespace lvox::rte
