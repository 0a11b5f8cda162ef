#pragma once
// Renders an image tile by tile with TBB. Each pixel owns a random stream derived from
// (seed, pixel index), so the image does not depend on the thread count or the order in
// which tiles run. Non-finite or negative samples are zeroed and counted: they never
// reach the image.
#include <atomic>
#include <cstdint>
#include <functional>

#include "src/core/image.h"
#include "src/core/rng.h"

namespace lvox {

struct TileStats {
  uint64_t samples = 0;
  uint64_t invalidSamples = 0;
};

class Progress {
 public:
  Progress(const char* label, uint64_t total);
  void advance(uint64_t n);
  void finish();

 private:
  const char* label_;
  uint64_t total_;
  std::atomic<uint64_t> done_{0};
  std::atomic<int> shownPercent_{-1};
  bool enabled_;
};

// `sample(x, y, rng)` returns one radiance sample of pixel (x, y); it is called spp times
// per pixel and the mean is stored.
using PixelSampler = std::function<RGB(int x, int y, Rng& rng)>;

Image renderTiles(int width, int height, int spp, uint64_t seed, const PixelSampler& sample,
                  TileStats& stats, const char* label = "render");

}  // namespace lvox
