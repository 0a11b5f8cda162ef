#pragma once
// One memory budget per render. Every large allocation a render can predict from its scene
// (the point cloud and its octree, the interreflection weights, the image buffers) is
// checked against it before it is made, so a setting that asks for too much ends at once
// with one line naming the setting, the bytes it needs and how to raise the limit, instead
// of an out-of-memory kill or a std::bad_alloc naming nothing minutes later.
// `check` tests an estimate without holding it; `reserve` holds bytes (thread-safe), for
// structures whose size is known only while they are built (reserved block by block).
#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>

namespace lvox {

class MemoryBudget {
 public:
  // 0: the default, 80 % of this machine's physical memory.
  explicit MemoryBudget(uint64_t limitBytes = 0);

  // Throws InputError(file, field, ...) when `bytes` more than what is reserved would pass
  // the limit; `what` says what needs them ("the point cloud", ...).
  void check(uint64_t bytes, const std::string& file, const std::string& field,
             const std::string& what) const;
  void reserve(uint64_t bytes, const std::string& file, const std::string& field,
               const std::string& what);
  // Holds `bytes` if they fit; false (nothing held) otherwise: for memory a render can do
  // without (a faster method's state).
  bool tryReserve(uint64_t bytes);
  uint64_t limit() const { return limit_; }
  uint64_t reserved() const { return reserved_.load(); }

 private:
  [[noreturn]] void fail(uint64_t bytes, const std::string& file, const std::string& field,
                         const std::string& what) const;
  uint64_t limit_;
  std::atomic<uint64_t> reserved_{0};
};

uint64_t physicalMemoryBytes();
// "512M", "4G", "1.5G", "800k" (powers of 1024) or plain bytes; InputError naming file and
// field otherwise, or below 1 MiB.
uint64_t parseByteSize(std::string_view text, const std::string& file, const std::string& field);
// "1.5 GB", "512 MB", "800 kB" (powers of 1024, one decimal).
std::string formatBytes(uint64_t bytes);

}  // namespace lvox
