#pragma once
// The progress line of a run: one line on the terminal, rewritten in place, naming the
// phase under way (scene_load, surfel_sampling, ..., interreflection, render) with its
// elapsed time and, where the phase knows its work, the share done and the time left:
//
//   lvox: render  42%  3.1 s, about 4.3 s left
//
// Phases are begun and ended by PhaseTimer (src/render/report.h), so every timed phase
// shows; a phase that knows its work calls addWork once and advance as it goes (from any
// thread). The share shown never goes back within a phase. Off unless enabled (the app
// enables it when stderr is a terminal and --quiet is not given): logs and pipes get only
// the summary line the app prints at the end.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

namespace lvox {

class Progress {
 public:
  // Where lines go and what time it is (tests replace both).
  struct Output {
    std::function<void(const std::string& text)> write;  // "\r<line>\033[K" or the clear
    std::function<double()> seconds;                     // a monotone clock
  };

  // The process's one progress line (stderr, a steady clock), disabled at first.
  static Progress& global();
  Progress();
  explicit Progress(Output output);

  void enable(bool on) { enabled_ = on; }
  bool enabled() const { return enabled_; }

  // Phases nest (a phase inside a phase shows while it runs, then the outer one again).
  void beginPhase(const std::string& name);
  void endPhase();
  // The current phase's work grows by `units` (call before advancing through them).
  void addWork(uint64_t units);
  // `units` of the current phase's work are done. Thread-safe; prints at most every 0.2 s.
  void advance(uint64_t units);

  // The line as it stands (for tests): "render  42%  3.1 s, about 4.3 s left".
  std::string line();

 private:
  std::string lineLocked(double now);
  struct Phase {
    std::string name;
    double start = 0.0;
    uint64_t total = 0;
    uint64_t doneBelow = 0;  // its work done when a nested phase began
    int shownPercent = 0;    // the largest share shown: never shown smaller
  };
  void print(double now);

  Output output_;
  bool enabled_ = false;
  std::mutex mutex_;
  std::vector<Phase> phases_;      // the stack of phases under way
  std::atomic<uint64_t> done_{0};  // of the innermost phase
  std::atomic<double> lastPrint_{-1.0};
};

// Begins a phase of the global progress line for its lifetime.
class ProgressPhase {
 public:
  explicit ProgressPhase(const std::string& name) { Progress::global().beginPhase(name); }
  ~ProgressPhase() { Progress::global().endPhase(); }
  ProgressPhase(const ProgressPhase&) = delete;
  ProgressPhase& operator=(const ProgressPhase&) = delete;
};

}  // namespace lvox
