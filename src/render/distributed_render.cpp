#include "src/render/distributed_render.h"

#include <algorithm>
#include <span>

#include "src/core/progress.h"

namespace lvox {
namespace {

void renderSampleRange(Film& film, uint64_t seed, const PixelSampler& sample,
                       const RenderPlan& plan, const Collective& team, TileStats& stats,
                       PixelMoments* moments) {
  const auto share = [&](int r) {
    return static_cast<int>(static_cast<int64_t>(plan.spp) * r / team.size());
  };
  const int begin = share(team.rank()), end = share(team.rank() + 1);
  if (end > begin)
    accumulateTiles(film, plan.firstSample + static_cast<uint64_t>(begin), end - begin, seed,
                    sample, stats, moments);
}

// The bands of rows, taken from the team's counter until none is left: `render(rowBegin,
// rowEnd)` each.
template <class RenderRows>
void forEachBand(const Film& film, Collective& team, RenderRows&& render) {
  const uint64_t bands = static_cast<uint64_t>((film.height() + kBandRows - 1) / kBandRows);
  team.resetCounter();
  for (uint64_t band = team.take(1); band < bands; band = team.take(1)) {
    const int rowBegin = static_cast<int>(band) * kBandRows;
    render(rowBegin, std::min(film.height(), rowBegin + kBandRows));
  }
}

// Adaptive samples over the ranks: the first samples' moments are summed (each rank holds
// its pixels' or its sample range's share), every rank plans the same extra samples, and
// they are split as the first ones were.
uint64_t renderExtraSamples(Film& film, uint64_t seed, const PixelSampler& sample,
                            const RenderPlan& plan, RenderSplit split, Collective& team,
                            TileStats& stats, PixelMoments& moments) {
  team.sum(std::span<double>(moments.sum));
  team.sum(std::span<double>(moments.squares));
  team.sum(std::span<uint64_t>(moments.count));
  std::vector<uint32_t> extra =
      adaptiveExtraSamples(moments, film.width(), film.height(), plan.spp, plan.adaptiveSpp);
  const uint64_t first = plan.firstSample + static_cast<uint64_t>(plan.spp);
  if (split == RenderSplit::kSampleRanges)
    accumulateExtraRows(film, 0, film.height(), first, extra, team.rank(), team.size(), seed,
                        sample, stats);
  else
    forEachBand(film, team, [&](int rowBegin, int rowEnd) {
      accumulateExtraRows(film, rowBegin, rowEnd, first, extra, 0, 1, seed, sample, stats);
    });
  film.setExtraSamples(std::move(extra));
  return film.extraSamples();
}

}  // namespace

RenderResult renderDistributed(int width, int height, uint64_t seed, const PixelSampler& sample,
                               const RenderPlan& plan, RenderSplit split, Collective& team,
                               TileStats& stats, Report& report) {
  Film film(width, height, plan.layers);
  const uint64_t pixels = static_cast<uint64_t>(width) * static_cast<uint64_t>(height);
  const bool adaptive = plan.adaptiveSpp > plan.spp;
  // Each rank's own share, about 1/N of the samples.
  Progress::global().addWork(pixels *
                             static_cast<uint64_t>(adaptive ? plan.adaptiveSpp : plan.spp) /
                             static_cast<uint64_t>(team.size()));
  PixelMoments moments(adaptive ? pixels : 0);
  PixelMoments* const firstMoments = adaptive ? &moments : nullptr;
  if (split == RenderSplit::kSampleRanges)
    renderSampleRange(film, seed, sample, plan, team, stats, firstMoments);
  else
    forEachBand(film, team, [&](int rowBegin, int rowEnd) {
      accumulateRows(film, rowBegin, rowEnd, plan.firstSample, plan.spp, seed, sample, stats,
                     firstMoments);
    });
  RenderResult result;
  if (adaptive)
    result.extraSamples = renderExtraSamples(film, seed, sample, plan, split, team, stats, moments);
  {
    PhaseTimer timer(report, "render_wait");  // for the slowest rank: the imbalance
    team.barrier();
  }
  {
    PhaseTimer timer(report, "render_exchange");  // the sum itself: the communication
    team.sum(floatsOf(film.beauty.pixels));
    if (film.hasLayers()) team.sum(std::span<double>(film.layerSums()));
  }
  result.sppDone = plan.spp;
  result.layers = film.layerChannels(plan.spp);
  result.image = film.beautyMean(plan.spp);
  return result;
}

}  // namespace lvox
