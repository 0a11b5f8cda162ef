#pragma once
// Method names (as in --solver and volume_integrator.solver) and their static properties.
#include <string>
#include <string_view>

namespace lvox::rte {

enum class Method {
  // Fixed-step IVP solvers on the (T, Q) system (see solve.h for the formulation).
  kEuler,
  kRk2,
  kRk4,
  kAb4,
  kBackwardEuler,
  kTrapezoid,
  kTrapezoidPc,
  // Adaptive embedded Runge-Kutta pairs.
  kRk12,
  kBs23,
  kRkf45,
  kCashKarp,
  kDopri5,
  kVerner56,
  // Quadrature rules on the integral form.
  kRectangle,
  kSimpson,
  kAdaptiveSimpson,
  kGaussKronrod,
  kMonteCarlo,
};

inline constexpr Method kAllMethods[] = {
    Method::kEuler,         Method::kRk2,       Method::kRk4,         Method::kAb4,
    Method::kBackwardEuler, Method::kTrapezoid, Method::kTrapezoidPc, Method::kRk12,
    Method::kBs23,          Method::kRkf45,     Method::kCashKarp,    Method::kDopri5,
    Method::kVerner56,      Method::kRectangle, Method::kSimpson,     Method::kAdaptiveSimpson,
    Method::kGaussKronrod,  Method::kMonteCarlo};

// Changes of variable (Munoz 2014 sec. 5: importance sampling as a reparametrisation).
enum class Sampling { kNone, kDistance, kEquiangular };

// The name used on the command line and in scene files ("rk4", "gauss-kronrod", ...).
std::string_view methodName(Method m);
std::string_view samplingName(Sampling s);

// "euler, rk2, ...": every method's name, for messages and --help.
std::string methodNames();

// name -> method; throws lvox::InputError(file, field, ...) listing the valid names,
// `alsoValid` first (a name the caller handles itself, such as "auto").
Method parseMethod(std::string_view name, const std::string& file = "volume_integrator",
                   const std::string& field = "solver", std::string_view alsoValid = {});
Sampling parseSampling(std::string_view name, const std::string& file = "volume_integrator",
                       const std::string& field = "sampling");

bool isAdaptive(Method m);    // step chosen from the tolerance
bool isQuadrature(Method m);  // integral form rather than an IVP

// Global order of the propagated solution on smooth problems (Monte Carlo: 0, it has an
// RMSE rate instead).
int methodOrder(Method m);

// Largest sigma_t*h for which a fixed step keeps T >= 0 and |R| <= 1 (oracles.md 2.5).
// Steps beyond it are subdivided and counted as stability events. Infinity: no limit.
double stepLimit(Method m);

}  // namespace lvox::rte
