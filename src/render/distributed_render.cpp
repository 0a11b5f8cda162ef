#include "src/render/distributed_render.h"

#include <algorithm>

namespace lvox {
namespace {

void renderSampleRange(Image& sum, uint64_t seed, const PixelSampler& sample,
                       const RenderPlan& plan, const Collective& team, TileStats& stats) {
  const auto share = [&](int r) {
    return static_cast<int>(static_cast<int64_t>(plan.spp) * r / team.size());
  };
  const int begin = share(team.rank()), end = share(team.rank() + 1);
  if (end > begin)
    accumulateTiles(sum, plan.firstSample + static_cast<uint64_t>(begin), end - begin, seed, sample,
                    stats);
}

void renderTileBands(Image& sum, uint64_t seed, const PixelSampler& sample, const RenderPlan& plan,
                     Collective& team, TileStats& stats) {
  const uint64_t bands = static_cast<uint64_t>((sum.height + kBandRows - 1) / kBandRows);
  team.resetCounter();
  for (uint64_t band = team.take(1); band < bands; band = team.take(1)) {
    const int rowBegin = static_cast<int>(band) * kBandRows;
    accumulateRows(sum, rowBegin, std::min(sum.height, rowBegin + kBandRows), plan.firstSample,
                   plan.spp, seed, sample, stats);
  }
}

}  // namespace

RenderResult renderDistributed(int width, int height, uint64_t seed, const PixelSampler& sample,
                               const RenderPlan& plan, RenderSplit split, Collective& team,
                               TileStats& stats, Report& report) {
  Image sum(width, height);
  if (split == RenderSplit::kSampleRanges)
    renderSampleRange(sum, seed, sample, plan, team, stats);
  else
    renderTileBands(sum, seed, sample, plan, team, stats);
  {
    PhaseTimer timer(report, "render_wait");  // for the slowest rank: the imbalance
    team.barrier();
  }
  {
    PhaseTimer timer(report, "render_exchange");  // the sum itself: the communication
    team.sum(floatsOf(sum.pixels));
  }
  RenderResult result;
  result.sppDone = plan.spp;
  for (RGB& p : sum.pixels) p /= static_cast<float>(plan.spp);
  result.image = std::move(sum);
  return result;
}

}  // namespace lvox
