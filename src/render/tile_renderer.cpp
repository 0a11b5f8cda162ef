#include "src/render/tile_renderer.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <atomic>

#include "src/core/progress.h"

namespace lvox {

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
  tbb::parallel_for(tbb::blocked_range2d<int>(rowBegin, rowEnd, kTile, 0, width, kTile),
                    [&](const tbb::blocked_range2d<int>& tile) {
                      uint64_t tileInvalid = 0;
                      for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
                        for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
                          RGB acc(0.0f);
                          PixelLayerSums layerSums{};
                          for (int s = 0; s < count; ++s) {
                            Rng rng = sampleRng(seed, width, x, y,
                                                firstSample + static_cast<uint64_t>(s));
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
                      Progress::global().advance(static_cast<uint64_t>(tile.rows().size()) *
                                                 tile.cols().size() * static_cast<uint64_t>(count));
                    });
  stats.samples += static_cast<uint64_t>(width) * rows * static_cast<uint64_t>(count);
  stats.invalidSamples += invalid.load();
}

}  // namespace lvox
