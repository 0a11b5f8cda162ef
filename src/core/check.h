#pragma once
// Invariants of the library code (not input checks: bad input is an InputError). A broken
// invariant is a bug in lvox; it throws std::logic_error naming the condition and its place,
// which the command line prints as one line ("lvox: error: internal error: ...") instead of
// crashing or rendering garbage.
//   LVOX_CHECK  stays in release builds: cold paths (setup, loading, phase boundaries).
//   LVOX_DCHECK is checked in debug builds only: hot paths (per sample, per ray, per element),
//               where release builds cannot afford it; its condition still compiles.
#include <stdexcept>
#include <string>

namespace lvox::detail {

[[noreturn]] inline void checkFailed(const char* condition, const std::string& what,
                                     const char* file, int line) {
  throw std::logic_error(std::string("internal error: ") + file + ":" + std::to_string(line) +
                         ": " + condition + " (" + what + ")");
}

}  // namespace lvox::detail

#define LVOX_CHECK(condition, what)                                                      \
  do {                                                                                   \
    if (!(condition)) ::lvox::detail::checkFailed(#condition, what, __FILE__, __LINE__); \
  } while (0)

#ifdef NDEBUG
#define LVOX_DCHECK(condition, what) \
  do {                               \
    if (false && (condition)) {      \
    }                                \
  } while (0)
#else
#define LVOX_DCHECK(condition, what) LVOX_CHECK(condition, what)
#endif
