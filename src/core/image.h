#pragma once
// A linear RGB float image, row-major from the top-left pixel.
#include <cstddef>
#include <vector>

#include "src/core/math.h"

namespace lvox {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<RGB> pixels;

  Image() = default;
  Image(int w, int h, RGB fill = RGB(0.0f))
      : width(w), height(h), pixels(static_cast<size_t>(w) * h, fill) {}
  RGB& at(int x, int y) { return pixels[static_cast<size_t>(y) * width + x]; }
  const RGB& at(int x, int y) const { return pixels[static_cast<size_t>(y) * width + x]; }
};

}  // namespace lvox
