#pragma once
// Error of an image against a reference, as `lvox compare` reports it.
#include <string>
#include <vector>

#include "src/core/image.h"

namespace lvox {

struct ImageError {
  double deltaPercent = 0.0;  // 100 * sum|A-B| / sum|B| over all pixels and channels
  double relMse = 0.0;        // mean of (A-B)^2 / (B^2 + 0.01): the epsilon keeps dark
                              // pixels from dominating (as in pbrt's and Mitsuba's tools)
  double rmse = 0.0;          // sqrt(mean (A-B)^2)
  double psnrDb = 0.0;        // 10 log10(peak^2 / MSE), peak = max of the reference;
                              // infinite for identical images
  double maxAbs = 0.0;        // max |A-B|
  double meanRatio = 1.0;     // sum A / sum B: the bias of the overall brightness
};

// Throws InputError naming `testName` when the sizes differ.
ImageError compareImages(const Image& test, const Image& reference,
                         const std::string& testName = "A", const std::string& referenceName = "B");

// Per-pixel relative error |A-B| / (|B| + 0.01), averaged over the channels.
std::vector<float> relativeErrorMap(const Image& test, const Image& reference);

}  // namespace lvox
