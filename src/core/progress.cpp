#include "src/core/progress.h"

#include <algorithm>
#include <cstdio>

namespace lvox {
namespace {

double steadySeconds() {
  using Clock = std::chrono::steady_clock;
  static const Clock::time_point origin = Clock::now();
  return std::chrono::duration<double>(Clock::now() - origin).count();
}

constexpr double kPrintInterval = 0.2;  // seconds between lines: a terminal keeps up

}  // namespace

Progress& Progress::global() {
  static Progress instance;
  return instance;
}

Progress::Progress()
    : Progress(Output{[](const std::string& text) {
                        std::fputs(text.c_str(), stderr);
                        std::fflush(stderr);
                      },
                      steadySeconds}) {}

Progress::Progress(Output output) : output_(std::move(output)) {}

void Progress::beginPhase(const std::string& name) {
  if (!enabled_) return;
  std::lock_guard lock(mutex_);
  if (!phases_.empty()) phases_.back().doneBelow = done_.load();
  done_ = 0;
  phases_.push_back({name, output_.seconds(), 0, 0, 0});
  print(output_.seconds());
}

void Progress::endPhase() {
  if (!enabled_) return;
  std::lock_guard lock(mutex_);
  if (phases_.empty()) return;
  phases_.pop_back();
  if (phases_.empty()) {
    output_.write("\r\033[K");  // the summary line takes its place
    return;
  }
  done_ = phases_.back().doneBelow;
  print(output_.seconds());
}

void Progress::addWork(uint64_t units) {
  if (!enabled_) return;
  std::lock_guard lock(mutex_);
  if (!phases_.empty()) phases_.back().total += units;
}

void Progress::advance(uint64_t units) {
  if (!enabled_) return;
  done_ += units;
  const double now = output_.seconds();
  if (now - lastPrint_ < kPrintInterval) return;
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (lock.owns_lock()) print(now);  // another thread is printing: it shows this too
}

std::string Progress::line() {
  std::lock_guard lock(mutex_);
  return lineLocked(output_.seconds());
}

std::string Progress::lineLocked(double now) {
  if (phases_.empty()) return "";
  Phase& p = phases_.back();
  const double elapsed = now - p.start;
  char buf[160];
  if (p.total == 0) {
    std::snprintf(buf, sizeof buf, "%s  %.1f s", p.name.c_str(), elapsed);
    return buf;
  }
  const uint64_t done = std::min(done_.load(), p.total);
  const int percent = static_cast<int>(100 * done / p.total);
  p.shownPercent = std::max(p.shownPercent, percent);
  if (done == 0) {
    std::snprintf(buf, sizeof buf, "%s  %3d%%  %.1f s", p.name.c_str(), p.shownPercent, elapsed);
    return buf;
  }
  const double left = elapsed * static_cast<double>(p.total - done) / static_cast<double>(done);
  std::snprintf(buf, sizeof buf, "%s  %3d%%  %.1f s, about %.1f s left", p.name.c_str(),
                p.shownPercent, elapsed, left);
  return buf;
}

void Progress::print(double now) {
  if (phases_.empty()) return;  // work outside any phase: no bare "lvox:" line
  lastPrint_ = now;
  output_.write("\rlvox: " + lineLocked(now) + "\033[K");
}

}  // namespace lvox
