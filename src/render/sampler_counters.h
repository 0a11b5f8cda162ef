#pragma once
// Counters the pixel samplers of every mode share (thread-safe, added to the report once).
#include <atomic>
#include <cstdint>

#include "src/render/report.h"

namespace lvox {

struct SamplerCounters {
  std::atomic<uint64_t> shadowRays{0};
  std::atomic<uint64_t> pathRays{0};
  std::atomic<uint64_t> paths{0};
  std::atomic<uint64_t> gatherRays{0};
  std::atomic<uint64_t> emitterRays{0};  // pcb: rays for the emitters seen directly
  std::atomic<uint64_t> mediumEvals{0};
  std::atomic<uint64_t> solverSteps{0};
  std::atomic<uint64_t> rejectedSteps{0};
  std::atomic<uint64_t> stabilityEvents{0};
  std::atomic<uint64_t> cappedSegments{0};

  void addTo(Report& report) const {
    auto put = [&](const char* name, const std::atomic<uint64_t>& v) {
      if (v.load() > 0) report.add(name, v.load());
    };
    put("shadow_rays", shadowRays);
    put("path_rays", pathRays);
    put("paths", paths);
    put("gather_rays", gatherRays);
    put("emitter_rays", emitterRays);
    report.add("medium_evals", mediumEvals.load());
    put("solver_steps", solverSteps);
    put("rejected_steps", rejectedSteps);
    put("stability_events", stabilityEvents);
    put("capped_segments", cappedSegments);
  }
};

}  // namespace lvox
