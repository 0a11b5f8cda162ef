#include "src/core/image_metrics.h"

#include <cmath>
#include <limits>

#include "src/core/error.h"

namespace lvox {

ImageError compareImages(const Image& test, const Image& reference, const std::string& testName,
                         const std::string& referenceName) {
  if (test.width != reference.width || test.height != reference.height)
    throw InputError(testName, "",
                     "is " + std::to_string(test.width) + "x" + std::to_string(test.height) +
                         " but the reference " + referenceName + " is " +
                         std::to_string(reference.width) + "x" + std::to_string(reference.height));
  // A non-finite value makes every sum meaningless (an all-NaN reference would read 0 %).
  for (const auto& [image, name] : {std::pair<const Image*, const std::string*>{&test, &testName},
                                    {&reference, &referenceName}})
    for (const RGB& p : image->pixels)
      if (!isFinite(p))
        throw InputError(*name, "", "holds NaN or infinite values: no error can be measured");
  double sumAbs = 0.0, sumRef = 0.0, sumTest = 0.0, sumSq = 0.0, sumRel = 0.0, peak = 0.0,
         maxAbs = 0.0;
  for (size_t i = 0; i < test.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double a = test.pixels[i][c], b = reference.pixels[i][c];
      const double d = a - b;
      sumAbs += std::abs(d);
      sumRef += std::abs(b);
      sumTest += std::abs(a);
      sumSq += d * d;
      sumRel += d * d / (b * b + 0.01);
      peak = std::max(peak, b);
      maxAbs = std::max(maxAbs, std::abs(d));
    }
  const double n = 3.0 * static_cast<double>(test.pixels.size());
  ImageError e;
  e.deltaPercent = sumRef > 0.0 ? 100.0 * sumAbs / sumRef
                                : (sumAbs > 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
  e.relMse = sumRel / n;
  const double mse = sumSq / n;
  e.rmse = std::sqrt(mse);
  e.psnrDb = mse > 0.0 ? 10.0 * std::log10((peak > 0.0 ? peak * peak : 1.0) / mse)
                       : std::numeric_limits<double>::infinity();
  e.maxAbs = maxAbs;
  e.meanRatio = sumRef > 0.0 ? sumTest / sumRef
                             : (sumTest > 0.0 ? std::numeric_limits<double>::infinity() : 1.0);
  return e;
}

std::vector<float> relativeErrorMap(const Image& test, const Image& reference) {
  std::vector<float> out(test.pixels.size());
  for (size_t i = 0; i < out.size(); ++i) {
    float sum = 0.0f;
    for (int c = 0; c < 3; ++c)
      sum += std::abs(test.pixels[i][c] - reference.pixels[i][c]) /
             (std::abs(reference.pixels[i][c]) + 0.01f);
    out[i] = sum / 3.0f;
  }
  return out;
}

}  // namespace lvox
