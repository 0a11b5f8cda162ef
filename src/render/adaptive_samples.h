#pragma once
// Adaptive camera samples (`render.adaptive_spp`; docs/pcb.md, "Adaptive samples").
//
// At 4 samples per pixel most of an image's per-pixel noise sits in a few pixels: shadow
// and silhouette edges, texture detail, the smoke's wisps. On Sponza with smoke.vdb 10 % of
// the pixels hold half of it (docs/results.md, stop 54). After the first `spp` samples of
// every pixel, the rest of a budget of `adaptive_spp` samples per pixel on average goes
// where the samples disagree: the expected sum of the pixels' absolute errors, the image's
// delta, is least when pixel i takes n_i ~ sigma_i^(2/3) samples (minimise sum sigma_i /
// sqrt(n_i) for a fixed sum of n_i), sigma_i the deviation of one of its samples.
//
// A pixel's deviation is read from its 8 neighbours' first samples, never from its own:
// its sample count then depends on no sample of its own, and its mean stays unbiased
// (samples are independent across pixels given the point cloud). A pixel's own first
// samples would give it fewer samples where they happened to agree, which biases the mean
// of a skewed pixel. Neighbours are as good a guide: edges and texture detail span pixels.
#include <cstdint>
#include <span>
#include <vector>

namespace lvox {

// The first samples' moments per pixel, of the mean of each sample's three channels.
struct PixelMoments {
  std::vector<double> sum, squares;
  std::vector<uint64_t> count;  // valid samples (invalid ones are dropped)

  explicit PixelMoments(size_t pixels = 0)
      : sum(pixels, 0.0), squares(pixels, 0.0), count(pixels, 0) {}
  // The sample variance of pixel i's samples (0 with fewer than two).
  double variance(size_t i) const;
};

// A pixel takes at most this many times the budget's mean.
inline constexpr int kMaxSamplesPerMean = 16;

// The samples each pixel takes beyond the first `spp`, from the first samples' moments:
// n_i = clamp(c * sigma_i^(2/3), spp, kMaxSamplesPerMean * meanSpp) with sigma_i the root of
// the mean variance of its (up to 8) neighbours, c such that the n_i add up to meanSpp per
// pixel, rounded in pixel order so that the extra samples add up to exactly
// (meanSpp - spp) per pixel. Where no neighbour varies, every pixel takes the same.
std::vector<uint32_t> adaptiveExtraSamples(const PixelMoments& moments, int width, int height,
                                           int spp, int meanSpp);

}  // namespace lvox
