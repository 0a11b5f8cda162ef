#pragma once
// A content hash of files (64-bit FNV-1a over their bytes, in order), written into image
// headers so that chunks of an edited scene or of changed assets are not merged. Not
// cryptographic: it tells versions of one's own files apart.
#include <string>
#include <vector>

namespace lvox {

// 16 hex digits; throws InputError naming a file that cannot be read.
std::string hashFiles(const std::vector<std::string>& paths);

}  // namespace lvox
