#include "src/render/progressive.h"

#include <algorithm>
#include <chrono>

#include "src/core/progress.h"

namespace lvox {
namespace {

// A pass that can be stopped: about half a second of work, so a stop request is honoured
// quickly and loses little (one sample at first, until a sample's time is known).
int stoppablePass(double secondsPerSample) {
  if (!(secondsPerSample > 0.0)) return 1;
  return static_cast<int>(std::clamp(0.5 / secondsPerSample, 1.0, 1e6));
}

}  // namespace

RenderResult renderProgressive(int width, int height, uint64_t seed, const PixelSampler& sample,
                               const RenderPlan& plan, TileStats& stats) {
  using Clock = std::chrono::steady_clock;
  RenderResult result;
  Film film(width, height, plan.layers);
  const uint64_t pixels = static_cast<uint64_t>(width) * static_cast<uint64_t>(height);
  const bool adaptive = plan.adaptiveSpp > plan.spp;
  Progress::global().addWork(pixels *
                             static_cast<uint64_t>(adaptive ? plan.adaptiveSpp : plan.spp));
  PixelMoments moments(adaptive ? pixels : 0);
  const bool progressive = plan.timeLimitSeconds > 0.0 || plan.reference != nullptr;
  const auto start = Clock::now();
  double secondsPerSample = 0.0;
  while (result.sppDone < plan.spp) {
    if (plan.stop && plan.stop->load()) {
      result.stopped = true;
      break;
    }
    // Doubling passes (1, 1, 2, 4, ...) when progressive, small ones when it may be
    // stopped, else everything at once.
    int pass = progressive ? std::max(1, result.sppDone)
               : plan.stop ? stoppablePass(secondsPerSample)
                           : plan.spp;
    pass = std::min(pass, plan.spp - result.sppDone);
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (plan.timeLimitSeconds > 0.0 && result.sppDone > 0) {
      const double remaining = plan.timeLimitSeconds - elapsed;
      const int affordable =
          secondsPerSample > 0.0 ? static_cast<int>(remaining / secondsPerSample) : pass;
      if (affordable < 1) break;
      pass = std::min(pass, affordable);
    }
    const auto passStart = Clock::now();
    accumulateTiles(film, plan.firstSample + static_cast<uint64_t>(result.sppDone), pass, seed,
                    sample, stats, adaptive ? &moments : nullptr);
    const double passSeconds = std::chrono::duration<double>(Clock::now() - passStart).count();
    secondsPerSample = passSeconds / pass;
    result.sppDone += pass;
    if (plan.reference) {
      ConvergencePoint point;
      point.spp = result.sppDone;
      point.seconds = std::chrono::duration<double>(Clock::now() - start).count();
      point.error =
          compareImages(film.beautyMean(result.sppDone), *plan.reference, "render", "reference");
      result.convergence.push_back(point);
    }
  }
  if (adaptive && result.sppDone == plan.spp && !(plan.stop && plan.stop->load())) {
    std::vector<uint32_t> extra =
        adaptiveExtraSamples(moments, width, height, plan.spp, plan.adaptiveSpp);
    accumulateExtraRows(film, 0, height, plan.firstSample + static_cast<uint64_t>(plan.spp), extra,
                        0, 1, seed, sample, stats);
    film.setExtraSamples(std::move(extra));
    result.extraSamples = film.extraSamples();
  }
  result.image = result.sppDone > 0 ? film.beautyMean(result.sppDone) : film.beauty;
  if (result.sppDone > 0) result.layers = film.layerChannels(result.sppDone);
  return result;
}

}  // namespace lvox
