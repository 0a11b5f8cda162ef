#pragma once
// Runs a pixel sampler over the image in passes: all at once, or progressively (1, 2, 4,
// ... samples in total) to honour a time budget or to record the error against a
// reference after every doubling. Because every sample has its own random stream, the
// image after n samples is the same whichever way it was reached.
#include <atomic>
#include <vector>

#include "src/core/collective.h"
#include "src/core/image.h"
#include "src/core/image_metrics.h"
#include "src/render/cloud_export.h"
#include "src/render/tile_renderer.h"

namespace lvox {

struct RenderPlan {
  int spp = 1;  // samples per pixel to render (the maximum with a budget)
  // Adaptive samples (adaptive_samples.h): after the `spp` of every pixel, more where the
  // neighbours' samples disagree, up to this mean per pixel; 0 (or spp): none. Not with a
  // time budget, a reference, or a first sample other than 0.
  int adaptiveSpp = 0;
  uint64_t firstSample = 0;          // index of the first sample: chunks of one reference
  double timeLimitSeconds = 0.0;     // 0: no budget
  const Image* reference = nullptr;  // record the error after each doubling
  // Set (by a signal handler) to stop after the pass under way: the result then holds the
  // samples finished so far. With it, passes take about half a second, so little work is
  // lost and a stop is quick.
  const std::atomic<bool>* stop = nullptr;
  // The processes the render is split over (distributed_render.h); null: this one alone.
  Collective* team = nullptr;
  // The AOV layers to write beside the beauty (layers.h); none by default.
  LayerSet layers;
  // Point-based modes: a copy of the point cloud as the render used it, for
  // --export-cloud (cloud_export.h); null: none.
  ExportedCloud* cloudOut = nullptr;
};

struct ConvergencePoint {
  int spp = 0;
  double seconds = 0.0;  // render time so far
  ImageError error;
};

struct RenderResult {
  Image image;                       // mean of the samples rendered
  std::vector<ExtraChannel> layers;  // the means of the plan's layers, as EXR channels
  int sppDone = 0;
  uint64_t extraSamples = 0;  // the adaptive samples beyond sppDone per pixel, in all
  bool stopped = false;       // plan.stop was set before every sample was done
  std::vector<ConvergencePoint> convergence;
};

RenderResult renderProgressive(int width, int height, uint64_t seed, const PixelSampler& sample,
                               const RenderPlan& plan, TileStats& stats);

}  // namespace lvox
