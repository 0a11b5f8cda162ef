#pragma once
// Renders an image tile by tile with TBB. Every sample owns a random stream derived from
// (seed, pixel index, sample index), so the image does not depend on the thread count or
// the order in which tiles run, and samples [a, b) rendered in one run are exactly those
// of a longer run: progressive passes and chunked references add up to the same image.
// Non-finite or negative samples are zeroed and counted: they never reach the image.
#include <cstdint>
#include <functional>
#include <span>

#include "src/core/image.h"
#include "src/core/rng.h"
#include "src/render/adaptive_samples.h"
#include "src/render/film.h"
#include "src/render/layers.h"

namespace lvox {

struct TileStats {
  uint64_t samples = 0;
  uint64_t invalidSamples = 0;
};

// One camera sample: its pixel and its position on the film (pixel (x, y) covers
// [x, x + 1) x [y, y + 1)).
struct PixelSample {
  int x, y;
  float filmX, filmY;
};

// `sample(s, rng, layers)` returns one radiance sample of pixel (s.x, s.y); when `layers`
// is not null (layers were asked for) it also fills them (layers.h).
using PixelSampler = std::function<RGB(const PixelSample& s, Rng& rng, SampleLayers* layers)>;

// The random stream of one sample.
inline Rng sampleRng(uint64_t seed, int width, int x, int y, uint64_t sampleIndex) {
  const uint64_t pixel = static_cast<uint64_t>(y) * static_cast<uint64_t>(width) + x;
  return Rng(seed, (pixel << 32) ^ sampleIndex);
}

// Where sample `sampleIndex` of pixel (x, y) lies: point sampleIndex of an Owen-scrambled
// (0,2)-sequence with the pixel's own scramble (low_discrepancy.h). A pixel's 4 samples
// cover its 2 x 2 quarters, its 16 its 4 x 4 sixteenths, and so on. Independent positions
// left the direct light of textured Sponza at 4 spp twice as noisy (docs/results.md,
// "Stratified samples"). The scramble depends on the seed, so seeds stay independent.
PixelSample pixelSample(uint64_t seed, int width, int x, int y, uint64_t sampleIndex);

// Adds samples [firstSample, firstSample + count) of every pixel to the film (unnormalised),
// with their layers when the film has any; with `moments`, also each valid sample's channel
// mean to its pixel's moments (adaptive_samples.h).
void accumulateTiles(Film& film, uint64_t firstSample, int count, uint64_t seed,
                     const PixelSampler& sample, TileStats& stats, PixelMoments* moments = nullptr);
// The same for the pixels of rows [rowBegin, rowEnd) only.
void accumulateRows(Film& film, int rowBegin, int rowEnd, uint64_t firstSample, int count,
                    uint64_t seed, const PixelSampler& sample, TileStats& stats,
                    PixelMoments* moments = nullptr);
// Adaptive samples: pixel i of rows [rowBegin, rowEnd) adds its samples [firstSample,
// firstSample + extra[i]), or of them the share [extra[i] part / parts, extra[i] (part + 1)
// / parts) (a render split by sample ranges over `parts` processes).
void accumulateExtraRows(Film& film, int rowBegin, int rowEnd, uint64_t firstSample,
                         std::span<const uint32_t> extra, int part, int parts, uint64_t seed,
                         const PixelSampler& sample, TileStats& stats);

}  // namespace lvox
