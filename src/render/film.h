#pragma once
// The sums a render accumulates: the beauty image (float RGB, as ever) and, when layers are
// asked for, the sums of each layer (layers.h) per pixel. Layer sums are doubles: the
// variance layer is a difference of sums of squares, which float sums over thousands of
// samples would cancel away. A pixel's samples are summed in a PixelLayerSums first and
// added to the film once per pixel and pass (tiles own their pixels: no race).
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "src/core/image.h"
#include "src/core/image_io.h"
#include "src/render/layers.h"

namespace lvox {

// Doubles per pixel when every layer is kept: five radiance layers, albedo and normal (3
// each), depth (distance sum, hit count) and variance (the beauty's sum and sum of squares).
inline constexpr int kMaxLayerSlots = 7 * 3 + 2 + 6;
using PixelLayerSums = std::array<double, kMaxLayerSlots>;

class Film {
 public:
  Film() = default;
  Film(int width, int height, LayerSet layers);

  int width() const { return beauty.width; }
  int height() const { return beauty.height; }
  const LayerSet& layers() const { return layers_; }
  bool hasLayers() const { return slots_ > 0; }
  // Bytes the layer sums take per pixel (for the memory budget).
  static uint64_t layerBytesPerPixel(const LayerSet& layers);

  // One valid sample of a pixel into `sums` (zeroed by the caller per pixel).
  void addSample(PixelLayerSums& sums, const RGB& radiance, const SampleLayers& sample) const;
  // A pixel's sums into the film.
  void addPixel(int x, int y, const PixelLayerSums& sums);
  // Whether every value a sample's layers would add is finite (a sample that is not is
  // dropped whole, like a sample whose radiance is not).
  bool finite(const SampleLayers& sample) const;

  // The layer sums as one span, for adding films over ranks (Collective::sum).
  std::vector<double>& layerSums() { return sums_; }

  // Adaptive samples (adaptive_samples.h): pixel i took `extra[i]` samples beyond the
  // `samples` every pixel took; the means below divide by its own count.
  void setExtraSamples(std::vector<uint32_t> extra) { extra_ = std::move(extra); }
  uint64_t extraSamples() const;  // their sum over the pixels
  // The means after `samples` samples per pixel (and the extra ones), as EXR channels
  // "direct.R", ..., "depth.Z", "coverage.Y", "variance.R", ...
  std::vector<ExtraChannel> layerChannels(int samples) const;
  // The beauty's mean per pixel: `beauty` / samples (and the extra ones).
  Image beautyMean(int samples) const;

  Image beauty;  // the sum of the samples' radiance

 private:
  int offset(Layer l) const { return offsets_[static_cast<int>(l)]; }
  LayerSet layers_;
  std::array<int, kLayerCount> offsets_{};
  int slots_ = 0;  // doubles per pixel
  std::vector<double> sums_;
  std::vector<uint32_t> extra_;  // empty: no pixel took more than `samples`

  double samplesOf(size_t pixel, int samples) const;
};

}  // namespace lvox
