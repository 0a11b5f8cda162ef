#include "src/core/work_budget.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

#include "src/core/error.h"

namespace lvox {
namespace {

constexpr const char* kField = "render.max_evaluations";

uint64_t derivedLimit(uint64_t cameraSamples) {
  return static_cast<uint64_t>(std::max(
      WorkBudget::kFloor, WorkBudget::kPerCameraSample * static_cast<double>(cameraSamples)));
}

}  // namespace

WorkBudget::WorkBudget(uint64_t limit, uint64_t cameraSamples, std::string file)
    : limit_(limit > 0 ? limit : derivedLimit(cameraSamples)), file_(std::move(file)) {}

void WorkBudget::charge(uint64_t evaluations, std::string_view phase) {
  const uint64_t total = spent_.fetch_add(evaluations, std::memory_order_relaxed) + evaluations;
  if (total > limit_) exhaust(total, phase, 1.0);
}

void WorkBudget::project(uint64_t spentInPhase, uint64_t done, uint64_t total,
                         std::string_view phase) {
  if (total == 0 || exhausted()) return;
  const double fraction = std::min(1.0, static_cast<double>(done) / static_cast<double>(total));
  const double before = static_cast<double>(spent()), inPhase = static_cast<double>(spentInPhase);
  // Too few samples to project from: only what was spent counts.
  const bool probed = fraction >= kProbeFraction;
  const double projected = before + (probed ? inPhase / fraction : inPhase);
  if (projected > static_cast<double>(limit_))
    exhaust(static_cast<uint64_t>(std::min(projected, 1.8e19)), phase, probed ? fraction : 1.0);
}

void WorkBudget::exhaust(uint64_t evaluations, std::string_view phase, double fractionDone) {
  if (claimed_.exchange(true)) return;
  char done[32];
  std::snprintf(done, sizeof done, "%.0f %%", 100.0 * fractionDone);
  message_ = std::string(phase) + (fractionDone < 1.0 ? " would need about " : " needed ") +
             formatCount(static_cast<double>(evaluations)) + " medium evaluations" +
             (fractionDone < 1.0 ? std::string(" (projected after ") + done + " of them)" : "") +
             ", past the budget of " + formatCount(static_cast<double>(limit_)) +
             "; raise it with --max-evaluations or " + kField +
             ", or lower the resolution, spp, tolerance or the media's density";
  exhausted_.store(true, std::memory_order_release);
}

void WorkBudget::throwIfExhausted() const {
  if (exhausted_.load(std::memory_order_acquire)) throw InputError(file_, kField, message_);
}

uint64_t parseEvaluationCount(std::string_view text, const std::string& file,
                              const std::string& field) {
  if (text == "auto") return 0;
  double value = 0.0;
  const char* end = text.data() + text.size();
  const auto [rest, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || rest != end || !std::isfinite(value))
    throw InputError(file, field,
                     "\"" + std::string(text) + "\": expected \"auto\" or a number such as 5e10");
  if (value < 1e6 || value > 1e18)
    throw InputError(file, field, "\"" + std::string(text) + "\": must be within [1e6, 1e18]");
  return static_cast<uint64_t>(value);
}

std::string formatCount(double count) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", count);
  return buf;
}

}  // namespace lvox
