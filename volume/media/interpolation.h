#pragma once
// How a voxel grid is read between voxel centres.
#include <string>
#include <string_view>

namespace lvox {

enum class Interpolation { Nearest, Trilinear, Tricubic };

// "nearest" | "trilinear" | "tricubic"; throws InputError(file, field, ...) otherwise.
Interpolation parseInterpolation(std::string_view name, const std::string& file,
                                 const std::string& field);
std::string_view interpolationName(Interpolation i);

}  // namespace lvox
