#pragma once
// One budget of work per render: the medium evaluations (density lookups) every phase
// spends, counted in the counters the phases already keep. Each solver segment is capped
// (volume_integrator.max_evaluations) and opaque media are cut where nothing behind is
// visible, but a render of many rays can still ask for hours of work without any one
// segment being at fault. The budget makes that a clear error instead of a render that
// seems to hang: the camera phase projects its total from the samples it has finished
// (after kProbeFraction of them) and stops at once when the projection passes the limit;
// the point-based caches, whose work per element is already capped, are charged as they
// finish. The limit is derived from the scene (kPerCameraSample evaluations per camera
// sample, at least kFloor) unless `render.max_evaluations` / `--max-evaluations` sets it.
#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>

namespace lvox {

class WorkBudget {
 public:
  static constexpr double kPerCameraSample = 1e6;
  static constexpr double kFloor = 1e10;  // about ten minutes of lookups on two cores
  static constexpr double kProbeFraction = 0.02;

  // `limit` 0: derived from the number of camera samples. `file` names the scene, whose
  // render.max_evaluations the error names.
  WorkBudget(uint64_t limit, uint64_t cameraSamples, std::string file);

  uint64_t limit() const { return limit_; }
  uint64_t spent() const { return spent_.load(std::memory_order_relaxed); }

  // Adds work a phase has done (thread-safe); `phase` names it in the error.
  void charge(uint64_t evaluations, std::string_view phase);
  // The camera phase: `spentInPhase` evaluations after `done` of its `total` samples.
  // Once kProbeFraction of them are done, a projected total past the limit exhausts the
  // budget (thread-safe; the first projection past it is the one reported).
  void project(uint64_t spentInPhase, uint64_t done, uint64_t total, std::string_view phase);
  bool exhausted() const { return exhausted_.load(std::memory_order_relaxed); }
  // Throws InputError(file, "render.max_evaluations", ...) when exhausted.
  void throwIfExhausted() const;

 private:
  void exhaust(uint64_t evaluations, std::string_view phase, double fractionDone);
  uint64_t limit_;
  std::string file_;
  std::atomic<uint64_t> spent_{0};
  std::atomic<bool> exhausted_{false};
  std::atomic<bool> claimed_{false};  // the first thread to exhaust writes the message
  std::string message_;
};

// "auto" -> 0; else a number of evaluations such as 5e10 (at least 1e6); InputError
// naming file and field otherwise.
uint64_t parseEvaluationCount(std::string_view text, const std::string& file,
                              const std::string& field);
// 3.2e+11 style, three significant digits.
std::string formatCount(double count);

}  // namespace lvox
