#pragma once
// Base64 (RFC 4648) of float32 planes, as the report page embeds HDR pixels: the bytes
// are little-endian whatever the host, because the page views them as a Float32Array.
#include <string>
#include <vector>

namespace lvox {

std::string base64Floats(const std::vector<float>& values);

}  // namespace lvox
