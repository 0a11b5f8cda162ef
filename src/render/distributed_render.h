#pragma once
// A render split over the ranks of a Collective (several processes, e.g. MPI ranks), by
// one of two rules, each giving the image one process renders:
//  - sample ranges (mc): rank r of N renders samples [first + spp r / N, first + spp (r+1)
//    / N) of every pixel, and the sums are added over the ranks: the image equals the
//    one-process render up to the order of the floating-point additions;
//  - bands of tiles (the other modes, whose samplers depend on the whole spp): ranks take
//    bands of 16 pixel rows from a shared counter until none is left (dynamic load
//    balancing: a rank that finds its bands cheap takes more), and every pixel is
//    rendered by exactly one rank: the image is the one-process image, bit for bit.
// Every rank receives the whole image. The calls into the Collective are per band and
// per image, never per sample.
#include "src/core/collective.h"
#include "src/render/progressive.h"
#include "src/render/report.h"
#include "src/render/tile_renderer.h"

namespace lvox {

enum class RenderSplit { kSampleRanges, kTileBands };

// Samples [plan.firstSample, plan.firstSample + plan.spp); the plan's budget, reference
// and stop request are not used (the app refuses them with several ranks). The report's
// "render_wait" (waiting for the slowest rank) and "render_exchange" (adding the images
// over the ranks) are parts of the caller's "render".
RenderResult renderDistributed(int width, int height, uint64_t seed, const PixelSampler& sample,
                               const RenderPlan& plan, RenderSplit split, Collective& team,
                               TileStats& stats, Report& report);

// The rows of a band, the unit of work of RenderSplit::kTileBands.
inline constexpr int kBandRows = 16;

}  // namespace lvox
