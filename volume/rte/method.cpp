#include "volume/rte/method.h"

#include <limits>

#include "src/core/error.h"
#include "src/core/names.h"

namespace lvox::rte {
namespace {

struct MethodInfo {
  Method method;
  std::string_view name;
  int order;
  double limit;
};

constexpr double kNoLimit = std::numeric_limits<double>::infinity();

// Limits on sigma*h per step (oracles.md 2.5). At a stability boundary |R| = 1 and nothing
// decays (midpoint: R(-2) = 1), so the limits sit where R still damps: Euler 1 (R = 0, its
// positivity limit), midpoint 1 (R = 1/2, the minimum of R), RK4 2 (R = 1/3, boundary
// 2.785), AB4 0.2 (boundary 0.3; beyond it RK4 takes the step), Simpson 2 (the panel's
// quadratic interpolation of exp(-tau) is still within 1%). The trapezoid's R < 0 beyond 2
// (handled by a backward-Euler step). The fixed-point corrector of trapezoid-pc contracts
// by sigma*h/2, so 1 keeps it converging to tol in a few iterations. Adaptive pairs control
// stability through their error estimate.
constexpr MethodInfo kInfo[] = {
    {Method::kEuler, "euler", 1, 1.0},
    {Method::kRk2, "rk2", 2, 1.0},
    {Method::kRk4, "rk4", 4, 2.0},
    {Method::kAb4, "ab4", 4, 0.2},
    {Method::kBackwardEuler, "backward-euler", 1, kNoLimit},
    {Method::kTrapezoid, "trapezoid", 2, 2.0},
    {Method::kTrapezoidPc, "trapezoid-pc", 2, 1.0},
    {Method::kRk12, "rk12", 2, kNoLimit},
    {Method::kBs23, "bs23", 3, kNoLimit},
    {Method::kRkf45, "rkf45", 4, kNoLimit},
    {Method::kCashKarp, "cashkarp", 5, kNoLimit},
    {Method::kDopri5, "dopri5", 5, kNoLimit},
    {Method::kVerner56, "verner56", 6, kNoLimit},
    {Method::kRectangle, "rectangle", 1, kNoLimit},
    {Method::kSimpson, "simpson", 4, 2.0},
    {Method::kAdaptiveSimpson, "adaptive-simpson", 4, kNoLimit},
    {Method::kGaussKronrod, "gauss-kronrod", 22, kNoLimit},
    {Method::kMonteCarlo, "monte-carlo", 0, kNoLimit},
};

const MethodInfo& info(Method m) {
  for (const MethodInfo& i : kInfo)
    if (i.method == m) return i;
  return kInfo[0];  // unreachable: every enumerator has a row
}

constexpr Named<Sampling> kSamplingNames[] = {{Sampling::kNone, "none"},
                                              {Sampling::kDistance, "distance"},
                                              {Sampling::kEquiangular, "equiangular"}};

}  // namespace

std::string_view methodName(Method m) { return info(m).name; }
int methodOrder(Method m) { return info(m).order; }
double stepLimit(Method m) { return info(m).limit; }
std::string_view samplingName(Sampling s) { return nameOf(s, kSamplingNames); }

bool isAdaptive(Method m) {
  switch (m) {
    case Method::kRk12:
    case Method::kBs23:
    case Method::kRkf45:
    case Method::kCashKarp:
    case Method::kDopri5:
    case Method::kVerner56:
    case Method::kAdaptiveSimpson:
    case Method::kGaussKronrod:
      return true;
    default:
      return false;
  }
}

bool isQuadrature(Method m) {
  return m == Method::kRectangle || m == Method::kSimpson || m == Method::kAdaptiveSimpson ||
         m == Method::kGaussKronrod || m == Method::kMonteCarlo;
}

std::string methodNames() {
  std::string names;
  for (const MethodInfo& i : kInfo) {
    if (!names.empty()) names += ", ";
    names += i.name;
  }
  return names;
}

Method parseMethod(std::string_view name, const std::string& file, const std::string& field,
                   std::string_view alsoValid) {
  for (const MethodInfo& i : kInfo)
    if (i.name == name) return i.method;
  std::string valid(alsoValid);
  if (!valid.empty()) valid += ", ";
  throw InputError(
      file, field,
      "unknown solver '" + std::string(name) + "' (valid: " + valid + methodNames() + ")");
}

Sampling parseSampling(std::string_view name, const std::string& file, const std::string& field) {
  return parseNamed(name, kSamplingNames, "sampling", file, field);
}

}  // namespace lvox::rte
