#include "src/world/obj_validate.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "src/core/error.h"

namespace lvox {
namespace {

bool isDigit(char c) { return c >= '0' && c <= '9'; }

// A number as tinyobjloader's tryParseDouble reads the start of [s, end): sign, digits,
// fraction, exponent, assembled as it does (mantissa * 5^e * 2^e, so 0e500 is NaN there);
// `fallback` where it fails.
double tinyObjNumber(const char* s, const char* end, double fallback) {
  const char* c = s;
  double sign = 1.0, mantissa = 0.0;
  if (c < end && (*c == '+' || *c == '-')) sign = *c++ == '-' ? -1.0 : 1.0;
  const bool leadingDot = c < end && *c == '.';
  if (!leadingDot && !(c < end && isDigit(*c))) return fallback;
  while (c < end && isDigit(*c)) mantissa = mantissa * 10 + (*c++ - '0');
  if (c < end && *c == '.') {
    double scale = 0.1;
    for (++c; c < end && isDigit(*c); ++c, scale *= 0.1) mantissa += (*c - '0') * scale;
  }
  int exponent = 0;
  if (c < end && (*c == 'e' || *c == 'E')) {
    ++c;
    int expSign = 1;
    if (c < end && (*c == '+' || *c == '-')) expSign = *c++ == '-' ? -1 : 1;
    if (!(c < end && isDigit(*c))) return fallback;
    for (; c < end && isDigit(*c); ++c) {
      if (exponent > 2147483647 / 10) return fallback;
      exponent = exponent * 10 + (*c - '0');
    }
    exponent *= expSign;
  }
  return sign * (exponent ? std::ldexp(mantissa * std::pow(5.0, exponent), exponent) : mantissa);
}

// The joint ids of one `vw` line after "vw ": "<vertex> <joint> <weight> <joint> <weight>...".
// True, with the joint's text in `what`, if tinyobjloader could not convert one to int.
bool badJoint(const char* token, std::string& what) {
  token += std::strspn(token, " \t");
  token += std::strcspn(token, " \t\r");  // the vertex id (atoi)
  while (*token != '\0') {
    float pair[2];
    const char* start = nullptr;
    for (int k = 0; k < 2; ++k) {
      token += std::strspn(token, " \t");
      const char* end = token + std::strcspn(token, " \t\r");
      if (k == 0) start = token;
      pair[k] = static_cast<float>(tinyObjNumber(token, end, k == 0 ? -1.0 : 0.0));
      token = end;
    }
    if (pair[0] < 0.0f) return false;  // tinyobjloader refuses the line itself
    if (!(pair[0] < 2147483648.0f)) {
      what = std::string(start, std::strcspn(start, " \t\r")).substr(0, 40);
      return true;
    }
    token += std::strspn(token, " \t\r");
  }
  return false;
}

}  // namespace

void validateObjBytes(std::string_view bytes, const std::string& path, const std::string& field) {
  size_t lineNumber = 0;
  for (size_t at = 0; at < bytes.size();) {
    // Lines end at \n, \r or \r\n, as tinyobjloader's safeGetline splits them.
    size_t end = at;
    while (end < bytes.size() && bytes[end] != '\n' && bytes[end] != '\r') ++end;
    const std::string_view view = bytes.substr(at, end - at);
    at = end + (end < bytes.size() && bytes[end] == '\r' && end + 1 < bytes.size() &&
                        bytes[end + 1] == '\n'
                    ? 2
                    : 1);
    ++lineNumber;
    const size_t first = view.find_first_not_of(" \t");
    if (first == std::string_view::npos || view.substr(first, 2) != "vw") continue;
    const std::string line(view);  // c_str: a NUL ends the line, as for tinyobjloader
    const char* token = line.c_str() + first;
    if (!(token[0] == 'v' && token[1] == 'w' && (token[2] == ' ' || token[2] == '\t'))) continue;
    std::string joint;
    if (badJoint(token + 3, joint))
      throw InputError(path, field,
                       "malformed OBJ: line " + std::to_string(lineNumber) +
                           ": skin weight joint id '" + joint + "' is not an int");
  }
}

void validateObj(const std::string& path, const std::string& field) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  validateObjBytes(bytes, path, field);
}

}  // namespace lvox
