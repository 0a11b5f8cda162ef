#pragma once
// What tinyobjloader trusts in an OBJ file, checked before it reads the file.
//
// tinyobjloader 2.0 (Debian 12) reads a `vw` line (skin weights, its own extension) as
// pairs of floats and converts each joint id to int without a range check: a joint id of
// 1e10, 21e3820 (infinite) or 0e500 (NaN in its arithmetic) is undefined behaviour (found
// by fuzzing, issue 16). lvox does not use skin weights, so such a line is refused with
// one line naming it; every other line is left to tinyobjloader.
#include <string>
#include <string_view>

namespace lvox {

// Throws InputError(path, field, "malformed OBJ: line N: ...") on the first bad `vw` line.
void validateObjBytes(std::string_view bytes, const std::string& path, const std::string& field);
void validateObj(const std::string& path, const std::string& field);

}  // namespace lvox
