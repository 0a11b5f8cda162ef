#include "src/core/file_hash.h"

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <vector>

#include "src/core/error.h"

namespace lvox {

std::string hashFiles(const std::vector<std::string>& paths) {
  constexpr uint64_t kOffset = 14695981039346656037ull, kPrime = 1099511628211ull;
  uint64_t h = kOffset;
  std::vector<char> buffer(1 << 20);
  for (const std::string& path : paths) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, "", std::string("cannot read: ") + std::strerror(errno));
    while (in) {
      in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
      const auto n = static_cast<size_t>(in.gcount());
      for (size_t i = 0; i < n; ++i) {
        h ^= static_cast<unsigned char>(buffer[i]);
        h *= kPrime;
      }
    }
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

}  // namespace lvox
