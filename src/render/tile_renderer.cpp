#include "src/render/tile_renderer.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <atomic>

#include "src/core/low_discrepancy.h"
#include "src/core/progress.h"

namespace lvox {

PixelSample pixelSample(uint64_t seed, int width, int x, int y, uint64_t sampleIndex) {
  // Scrambles from (seed, pixel), unrelated to the samples' PCG streams, which mix the
  // seed the other way round.
  const uint64_t pixel =
      static_cast<uint64_t>(y) * static_cast<uint64_t>(width) + static_cast<uint64_t>(x);
  const uint64_t h = splitMix64(pixel ^ (seed * 0xd1b54a32d192ed03ull));
  // The sequence repeats after 2^32 samples of one pixel.
  const UnitPoint2 p = scrambledSobol2(static_cast<uint32_t>(sampleIndex), static_cast<uint32_t>(h),
                                       static_cast<uint32_t>(h >> 32));
  return {x, y, static_cast<float>(x) + p.u, static_cast<float>(y) + p.v};
}

void accumulateTiles(Film& film, uint64_t firstSample, int count, uint64_t seed,
                     const PixelSampler& sample, TileStats& stats) {
  accumulateRows(film, 0, film.height(), firstSample, count, seed, sample, stats);
}

namespace {

bool validRadiance(const RGB& v) {
  return isFinite(v) && v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f;
}

}  // namespace

void accumulateRows(Film& film, int rowBegin, int rowEnd, uint64_t firstSample, int count,
                    uint64_t seed, const PixelSampler& sample, TileStats& stats) {
  constexpr int kTile = 16;
  const int width = film.width();
  const int rows = rowEnd - rowBegin;
  const bool layered = film.hasLayers();
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
              const PixelSample at =
                  pixelSample(seed, width, x, y, firstSample + static_cast<uint64_t>(s));
              SampleLayers layers;
              const RGB v = sample(at, rng, layered ? &layers : nullptr);
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
        Progress::global().advance(static_cast<uint64_t>(tile.rows().size()) * tile.cols().size() *
                                   static_cast<uint64_t>(count));
      });
  stats.samples += static_cast<uint64_t>(width) * rows * static_cast<uint64_t>(count);
  stats.invalidSamples += invalid.load();
}

}  // namespace lvox
