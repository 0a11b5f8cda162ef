#pragma once
// What every EXR reader checks of an opened file before reading pixels: that it is complete
// and that its data window has a usable size. For the .cpp files that include OpenEXR.
#include <ImfHeader.h>
#include <ImfInputFile.h>

#include <string>

#include "src/core/error.h"

namespace lvox {

struct ExrSize {
  int width = 0, height = 0;
  Imath::Box2i window;  // the data window
};

inline ExrSize checkedExrSize(const std::string& path, Imf::InputFile& in) {
  if (!in.isComplete()) throw InputError(path, "", "the EXR file is incomplete (truncated?)");
  const Imath::Box2i dw = in.header().dataWindow();
  const long long w = static_cast<long long>(dw.max.x) - dw.min.x + 1;
  const long long h = static_cast<long long>(dw.max.y) - dw.min.y + 1;
  if (w <= 0 || h <= 0 || w * h > (1ll << 30) || w > (1ll << 24))
    throw InputError(path, "", "the EXR data window has an unusable size");
  return {static_cast<int>(w), static_cast<int>(h), dw};
}

}  // namespace lvox
