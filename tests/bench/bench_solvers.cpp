// Cost of the RTE methods per step and per medium evaluation, on a smooth heterogeneous
// segment (sigma_t and the source vary along t) with a cheap closed-form medium, so
// the numbers are the solvers' own overhead:
//   build/tests/bench/lvox_bench --benchmark_filter=RteSolve
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

#include "volume/rte/method.h"
#include "volume/rte/solve.h"

namespace lvox {
namespace {

struct SmoothMedium {
  rte::MediumSample<float> eval(float t) const {
    const float sigma = 1.0f + 0.5f * std::sin(3.0f * t);
    const float source = 0.5f + 0.25f * std::cos(2.0f * t);
    return {rte::Channels<float>(sigma), rte::Channels<float>(source)};
  }
};

void RteSolve(benchmark::State& state, rte::Method method) {
  rte::SolveSettings<float> settings;
  settings.step = 0.05f;
  settings.tolerance = 1e-4f;
  settings.jitter = 0.5f;
  const SmoothMedium medium;
  uint64_t steps = 0, evals = 0;
  for (auto _ : state) {
    const rte::SolveResult<float> r =
        rte::solve(method, medium, 0.0f, 4.0f, rte::Channels<float>(0.0f), settings);
    benchmark::DoNotOptimize(r.radiance);
    steps += r.counts.steps;
    evals += r.counts.mediumEvals;
  }
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
  state.counters["evals_per_solve"] =
      static_cast<double>(evals) / static_cast<double>(state.iterations());
  state.counters["steps_per_solve"] =
      static_cast<double>(steps) / static_cast<double>(state.iterations());
}

const int kRegistered = [] {
  for (const rte::Method m : rte::kAllMethods)
    benchmark::RegisterBenchmark(("RteSolve/" + std::string(rte::methodName(m))).c_str(), RteSolve,
                                 m);
  return 0;
}();

}  // namespace
}  // namespace lvox
