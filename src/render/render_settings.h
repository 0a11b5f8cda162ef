#pragma once
// Settings of a render (the scene file's "render" section and the --mode, --spp,
// --max-bounces, --seed and --threads flags), typed, with their parser beside them.
#include <cstdint>
#include <string>
#include <string_view>

#include "src/core/json_fields.h"
#include "src/core/setting_list.h"

namespace lvox {

// pcb: point-based GI with lvoxels in media; pcb-surfels: the traditional baseline
// (surfels only, exact single scattering in media); direct: direct light and single
// scattering; mc: the unbiased path tracer everything is measured against.
enum class Mode { kPcb, kPcbSurfels, kDirect, kMc };

struct RenderSettings {
  Mode mode = Mode::kPcb;
  int spp = 4;
  // Adaptive samples (adaptive_samples.h): after `spp` samples of every pixel, more where
  // its neighbours' samples disagree, up to this mean per pixel; 0: none; kAutoAdaptive
  // ("auto", the default): adaptiveSamplesFor below.
  int adaptiveSpp = kAutoAdaptive;
  static constexpr int kAutoAdaptive = -1;
  int maxBounces = 8;
  uint64_t seed = 1;
  int areaLightSamples = 16;   // shadow rays per area light (and environment) at a surface point
  int mediumLightSamples = 1;  // the same at each medium evaluation (fixed along a camera ray)
  // pcb modes: rays per camera sample for the emission of emitters seen directly, in the
  // pixels near one (src/render/emitter_pixels.h); 1: the camera ray's own.
  int emitterSamples = 16;
  int threads = 0;  // 0: all cores
  // Memory budget of the render in bytes ("max_memory": "4G", or --max-memory); 0: 80 % of
  // the machine's memory (src/core/memory_budget.h). It does not change the image.
  uint64_t maxMemory = 0;
  // Budget of medium evaluations for the whole render ("max_evaluations": "5e10", or
  // --max-evaluations); 0: derived from the camera samples (src/core/work_budget.h). It
  // does not change the image.
  uint64_t maxEvaluations = 0;
};

// The mean samples per pixel a render takes with adaptive samples, 0 for none. "auto":
// 3/2 of spp (rounded up) in the point-based modes from 2 spp on (one sample per pixel
// tells no variance), none in mc and direct (the references and the baseline keep even
// samples); docs/results.md, stop 54, has what it gives.
int adaptiveSamplesFor(const RenderSettings& s);

// Reads the "render" object; unknown keys and out-of-range values throw.
RenderSettings parseRenderSettings(JsonObject r);
// The fields that change an image, as "render.<key>": all but spp (chunks of one image
// differ in it) and threads (images do not depend on it).
SettingList describe(const RenderSettings& s);

Mode parseMode(std::string_view name, const std::string& file, const std::string& field);
std::string_view modeName(Mode mode);
std::string modeNames();  // "pcb, pcb-surfels, direct, mc", for --help
// The two-phase modes, which build a point cloud.
inline bool isPointBased(Mode mode) { return mode == Mode::kPcb || mode == Mode::kPcbSurfels; }

}  // namespace lvox
