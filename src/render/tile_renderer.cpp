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
                     const PixelSampler& sample, TileStats& stats, PixelMoments* moments) {
  accumulateRows(film, 0, film.height(), firstSample, count, seed, sample, stats, moments);
}

namespace {

bool validRadiance(const RGB& v) {
  return isFinite(v) && v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f;
}

// Samples [first, first + count) of pixel (x, y) into the film; the invalid ones are
// counted and dropped. With `moments`, each valid sample's channel mean joins the pixel's.
uint64_t samplePixel(Film& film, int x, int y, uint64_t first, uint64_t count, uint64_t seed,
                     const PixelSampler& sample, PixelMoments* moments) {
  const int width = film.width();
  const bool layered = film.hasLayers();
  uint64_t invalid = 0;
  RGB acc(0.0f);
  PixelLayerSums layerSums{};
  const size_t pixel = static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
  for (uint64_t s = first; s < first + count; ++s) {
    Rng rng = sampleRng(seed, width, x, y, s);
    const PixelSample at = pixelSample(seed, width, x, y, s);
    SampleLayers layers;
    const RGB v = sample(at, rng, layered ? &layers : nullptr);
    if (!validRadiance(v) || (layered && !film.finite(layers))) {
      ++invalid;
      continue;
    }
    acc += v;
    if (layered) film.addSample(layerSums, v, layers);
    if (moments) {
      const double m = (static_cast<double>(v.x) + v.y + v.z) / 3.0;
      moments->sum[pixel] += m;
      moments->squares[pixel] += m * m;
      ++moments->count[pixel];
    }
  }
  film.beauty.at(x, y) += acc;
  if (layered) film.addPixel(x, y, layerSums);
  return invalid;
}

// Every pixel of rows [rowBegin, rowEnd) in tiles, in parallel; `range(x, y)` gives the
// pixel's samples as {first, count}.
template <class Range>
void accumulateRanges(Film& film, int rowBegin, int rowEnd, uint64_t seed,
                      const PixelSampler& sample, TileStats& stats, PixelMoments* moments,
                      Range&& range) {
  constexpr int kTile = 16;
  std::atomic<uint64_t> invalid{0}, done{0};
  tbb::parallel_for(tbb::blocked_range2d<int>(rowBegin, rowEnd, kTile, 0, film.width(), kTile),
                    [&](const tbb::blocked_range2d<int>& tile) {
                      uint64_t tileInvalid = 0, tileSamples = 0;
                      for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
                        for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
                          const auto [first, count] = range(x, y);
                          tileInvalid +=
                              samplePixel(film, x, y, first, count, seed, sample, moments);
                          tileSamples += count;
                        }
                      invalid += tileInvalid;
                      done += tileSamples;
                      Progress::global().advance(tileSamples);
                    });
  stats.samples += done.load();
  stats.invalidSamples += invalid.load();
}

}  // namespace

void accumulateRows(Film& film, int rowBegin, int rowEnd, uint64_t firstSample, int count,
                    uint64_t seed, const PixelSampler& sample, TileStats& stats,
                    PixelMoments* moments) {
  accumulateRanges(film, rowBegin, rowEnd, seed, sample, stats, moments, [&](int, int) {
    return std::pair<uint64_t, uint64_t>(firstSample, static_cast<uint64_t>(count));
  });
}

void accumulateExtraRows(Film& film, int rowBegin, int rowEnd, uint64_t firstSample,
                         std::span<const uint32_t> extra, int part, int parts, uint64_t seed,
                         const PixelSampler& sample, TileStats& stats) {
  const auto w = static_cast<size_t>(film.width());
  accumulateRanges(film, rowBegin, rowEnd, seed, sample, stats, nullptr, [&](int x, int y) {
    const uint64_t e = extra[static_cast<size_t>(y) * w + static_cast<size_t>(x)];
    const uint64_t begin = e * static_cast<uint64_t>(part) / static_cast<uint64_t>(parts);
    const uint64_t end = e * static_cast<uint64_t>(part + 1) / static_cast<uint64_t>(parts);
    return std::pair<uint64_t, uint64_t>(firstSample + begin, end - begin);
  });
}

}  // namespace lvox
