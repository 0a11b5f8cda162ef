#include "src/app/base64.h"

#include <array>
#include <cstdint>
#include <cstring>

namespace lvox {
namespace {

constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

void appendGroup(std::string& out, const uint8_t* b, size_t n) {
  const uint32_t v =
      (uint32_t{b[0]} << 16) | (n > 1 ? uint32_t{b[1]} << 8 : 0u) | (n > 2 ? uint32_t{b[2]} : 0u);
  out += kAlphabet[(v >> 18) & 63];
  out += kAlphabet[(v >> 12) & 63];
  out += n > 1 ? kAlphabet[(v >> 6) & 63] : '=';
  out += n > 2 ? kAlphabet[v & 63] : '=';
}

}  // namespace

std::string base64Floats(const std::vector<float>& values) {
  std::vector<uint8_t> bytes(values.size() * 4);
  for (size_t i = 0; i < values.size(); ++i) {
    uint32_t bits = 0;
    std::memcpy(&bits, &values[i], 4);
    for (size_t k = 0; k < 4; ++k) bytes[4 * i + k] = static_cast<uint8_t>(bits >> (8 * k));
  }
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3)
    appendGroup(out, bytes.data() + i, std::min<size_t>(3, bytes.size() - i));
  return out;
}

}  // namespace lvox
