#include "src/render/distributed_render.h"

#include <algorithm>
#include <span>

#include "src/core/progress.h"

namespace lvox {
namespace {

void renderSampleRange(Film& film, uint64_t seed, const PixelSampler& sample,
                       const RenderPlan& plan, const Collective& team, TileStats& stats) {
  const auto share = [&](int r) {
    return static_cast<int>(static_cast<int64_t>(plan.spp) * r / team.size());
  };
  const int begin = share(team.rank()), end = share(team.rank() + 1);
  if (end > begin)
    accumulateTiles(film, plan.firstSample + static_cast<uint64_t>(begin), end - begin, seed,
                    sample, stats);
}

void renderTileBands(Film& film, uint64_t seed, const PixelSampler& sample, const RenderPlan& plan,
                     Collective& team, TileStats& stats) {
  const uint64_t bands = static_cast<uint64_t>((film.height() + kBandRows - 1) / kBandRows);
  team.resetCounter();
  for (uint64_t band = team.take(1); band < bands; band = team.take(1)) {
    const int rowBegin = static_cast<int>(band) * kBandRows;
    accumulateRows(film, rowBegin, std::min(film.height(), rowBegin + kBandRows), plan.firstSample,
                   plan.spp, seed, sample, stats);
  }
}

}  // namespace

RenderResult renderDistributed(int width, int height, uint64_t seed, const PixelSampler& sample,
                               const RenderPlan& plan, RenderSplit split, Collective& team,
                               TileStats& stats, Report& report) {
  Film film(width, height, plan.layers);
  // Each rank's own share, about 1/N of the samples.
  Progress::global().addWork(static_cast<uint64_t>(width) * height *
                             static_cast<uint64_t>(plan.spp) / static_cast<uint64_t>(team.size()));
  if (split == RenderSplit::kSampleRanges)
    renderSampleRange(film, seed, sample, plan, team, stats);
  else
    renderTileBands(film, seed, sample, plan, team, stats);
  {
    PhaseTimer timer(report, "render_wait");  // for the slowest rank: the imbalance
    team.barrier();
  }
  {
    PhaseTimer timer(report, "render_exchange");  // the sum itself: the communication
    team.sum(floatsOf(film.beauty.pixels));
    if (film.hasLayers()) team.sum(std::span<double>(film.layerSums()));
  }
  RenderResult result;
  result.sppDone = plan.spp;
  result.layers = film.layerChannels(plan.spp);
  result.image = std::move(film.beauty);
  for (RGB& p : result.image.pixels) p /= static_cast<float>(plan.spp);
  return result;
}

}  // namespace lvox
