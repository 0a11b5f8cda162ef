#pragma once
// A complete check of a PLY file before assimp reads it. Assimp 5.2 trusts what the file
// says: a truncated body, a negative or out-of-range face index, or a 200-byte header that
// claims 10^9 vertices made it abort, crash, or allocate 11.7 GB for 27 s (issue 16).
// So the header is parsed here, every element count is bounded by the file's size before
// anything is allocated, and the whole body (ascii or binary, either byte order) is walked
// once: every declared instance must be present and well-formed, and every face index must
// name an existing vertex. Only a file that passes is handed to assimp.
#include <cstdint>
#include <string>
#include <string_view>

namespace lvox {

struct PlySummary {
  uint64_t vertices = 0;
  uint64_t faces = 0;
};

// Throws InputError(path, field, "malformed PLY: ...") on the first problem.
PlySummary validatePly(const std::string& path, const std::string& field);

// The same check on bytes in memory; `path` and `field` only name the error.
PlySummary validatePlyBytes(std::string_view bytes, const std::string& path,
                            const std::string& field);

}  // namespace lvox
