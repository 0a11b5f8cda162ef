#include "volume/media/interpolation.h"

#include "src/core/names.h"

namespace lvox {
namespace {
constexpr Named<Interpolation> kInterpolationNames[] = {{Interpolation::Nearest, "nearest"},
                                                        {Interpolation::Trilinear, "trilinear"},
                                                        {Interpolation::Tricubic, "tricubic"}};
}  // namespace

Interpolation parseInterpolation(std::string_view name, const std::string& file,
                                 const std::string& field) {
  return parseNamed(name, kInterpolationNames, "interpolation", file, field);
}

std::string_view interpolationName(Interpolation i) { return nameOf(i, kInterpolationNames); }

}  // namespace lvox
