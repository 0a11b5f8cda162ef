#include "src/core/memory_budget.h"

#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>

#include "src/core/error.h"

namespace lvox {

uint64_t physicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || pageSize <= 0) return uint64_t(8) << 30;  // unknown: assume 8 GB
  return static_cast<uint64_t>(pages) * static_cast<uint64_t>(pageSize);
}

MemoryBudget::MemoryBudget(uint64_t limitBytes)
    : limit_(limitBytes > 0 ? limitBytes : physicalMemoryBytes() / 5 * 4) {}

void MemoryBudget::check(uint64_t bytes, const std::string& file, const std::string& field,
                         const std::string& what) const {
  const uint64_t held = reserved_.load();
  if (bytes > limit_ || held > limit_ - bytes) fail(bytes, file, field, what);
}

void MemoryBudget::reserve(uint64_t bytes, const std::string& file, const std::string& field,
                           const std::string& what) {
  if (!tryReserve(bytes)) fail(bytes, file, field, what);
}

bool MemoryBudget::tryReserve(uint64_t bytes) {
  uint64_t held = reserved_.load();
  do {
    if (bytes > limit_ || held > limit_ - bytes) return false;
  } while (!reserved_.compare_exchange_weak(held, held + bytes));
  return true;
}

void MemoryBudget::fail(uint64_t bytes, const std::string& file, const std::string& field,
                        const std::string& what) const {
  throw InputError(file, field,
                   what + " needs about " + formatBytes(bytes) + " more, past the memory budget of " +
                       formatBytes(limit_) + " (" + formatBytes(reserved_.load()) +
                       " already held); raise it with --max-memory or render.max_memory, or "
                       "change this setting");
}

uint64_t parseByteSize(std::string_view text, const std::string& file, const std::string& field) {
  auto bad = [&](const std::string& why) -> uint64_t {
    throw InputError(file, field, "\"" + std::string(text) + "\": " + why);
  };
  double value = 0.0;
  const char* end = text.data() + text.size();
  const auto [rest, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || !std::isfinite(value) || value < 0.0)
    return bad("expected a size such as 512M, 4G or a number of bytes");
  const std::string_view unit(rest, static_cast<size_t>(end - rest));
  double scale = 1.0;
  if (unit == "k" || unit == "K" || unit == "kB" || unit == "KB")
    scale = 1024.0;
  else if (unit == "M" || unit == "MB")
    scale = 1024.0 * 1024.0;
  else if (unit == "G" || unit == "GB")
    scale = 1024.0 * 1024.0 * 1024.0;
  else if (unit == "T" || unit == "TB")
    scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
  else if (!unit.empty())
    return bad("unknown unit \"" + std::string(unit) + "\" (k, M, G or T)");
  const double bytes = value * scale;
  if (bytes < 1024.0 * 1024.0) return bad("must be at least 1M");
  if (bytes > 9e18) return bad("too large");
  return static_cast<uint64_t>(bytes);
}

std::string formatBytes(uint64_t bytes) {
  const char* units[] = {"B", "kB", "MB", "GB", "TB"};
  double v = static_cast<double>(bytes);
  int u = 0;
  while (v >= 1024.0 && u < 4) {
    v /= 1024.0;
    ++u;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.1f %s", v, units[u]);
  return buf;
}

}  // namespace lvox
