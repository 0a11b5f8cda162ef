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

void accumulateTiles(Film& film, uint64_t firstSample, int count, uint64_t seed,
                     const PixelSampler& sample, TileStats& stats, const char* label) {
  accumulateRows(film, 0, film.height(), firstSample, count, seed, sample, stats, label);
}

namespace {

bool validRadiance(const RGB& v) {
  return isFinite(v) && v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f;
}

}  // namespace

void accumulateRows(Film& film, int rowBegin, int rowEnd, uint64_t firstSample, int count,
                    uint64_t seed, const PixelSampler& sample, TileStats& stats,
                    const char* label) {
  constexpr int kTile = 16;
  const int width = film.width();
  const int rows = rowEnd - rowBegin;
  const bool layered = film.hasLayers();
  Progress progress(label, static_cast<uint64_t>(width) * rows);
  std::atomic<uint64_t> invalid{0};
  tbb::parallel_for(
      tbb::blocked_range2d<int>(rowBegin, rowEnd, kTile, 0, width, kTile),
      [&](const tbb::blocked_range2d<int>& tile) {
        uint64_t tileInvalid = 0;
        for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
          for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
            RGB acc(0.0f);
            PixelLayerSums layerSums{};
            for (int s = 0; s < count; ++s) {
              Rng rng = sampleRng(seed, width, x, y, firstSample + static_cast<uint64_t>(s));
              SampleLayers layers;
              const RGB v = sample(x, y, rng, layered ? &layers : nullptr);
              if (!validRadiance(v) || (layered && !film.finite(layers))) {
                ++tileInvalid;
                continue;
              }
              acc += v;
              if (layered) film.addSample(layerSums, v, layers);
            }
            film.beauty.at(x, y) += acc;
            if (layered) film.addPixel(x, y, layerSums);
          }
        invalid += tileInvalid;
        progress.advance(static_cast<uint64_t>(tile.rows().size()) * tile.cols().size());
      });
  progress.finish();
  stats.samples += static_cast<uint64_t>(width) * rows * static_cast<uint64_t>(count);
  stats.invalidSamples += invalid.load();
}

}  // namespace lvox
