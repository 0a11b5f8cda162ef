#include "src/render/tile_renderer.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <cstdio>

namespace lvox {

Progress::Progress(const char* label, uint64_t total)
    : label_(label), total_(total), enabled_(isatty(STDERR_FILENO) != 0) {}

void Progress::advance(uint64_t n) {
  if (!enabled_ || total_ == 0) return;
  const uint64_t done = done_.fetch_add(n) + n;
  const int percent = static_cast<int>(100 * done / total_);
  int shown = shownPercent_.load();
  // Only the thread that moves the percentage forward prints.
  while (percent > shown) {
    if (shownPercent_.compare_exchange_weak(shown, percent)) {
      std::fprintf(stderr, "\r%s: %3d%%", label_, percent);
      std::fflush(stderr);
      break;
    }
  }
}

void Progress::finish() {
  if (enabled_) std::fprintf(stderr, "\r\033[K");
}

Image renderTiles(int width, int height, int spp, uint64_t seed, const PixelSampler& sample,
                  TileStats& stats, const char* label) {
  Image image(width, height);
  constexpr int kTile = 16;
  Progress progress(label, static_cast<uint64_t>(width) * height);
  std::atomic<uint64_t> invalid{0};
  tbb::parallel_for(
      tbb::blocked_range2d<int>(0, height, kTile, 0, width, kTile),
      [&](const tbb::blocked_range2d<int>& tile) {
        uint64_t tileInvalid = 0;
        for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
          for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
            Rng rng(seed, static_cast<uint64_t>(y) * static_cast<uint64_t>(width) + x);
            RGB sum(0.0f);
            for (int s = 0; s < spp; ++s) {
              RGB v = sample(x, y, rng);
              if (!isFinite(v) || v.x < 0.0f || v.y < 0.0f || v.z < 0.0f) {
                ++tileInvalid;
                continue;
              }
              sum += v;
            }
            image.at(x, y) = sum / static_cast<float>(spp);
          }
        invalid += tileInvalid;
        progress.advance(static_cast<uint64_t>(tile.rows().size()) * tile.cols().size());
      });
  progress.finish();
  stats.samples = static_cast<uint64_t>(width) * height * spp;
  stats.invalidSamples = invalid.load();
  return image;
}

}  // namespace lvox
