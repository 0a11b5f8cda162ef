#pragma once
// What a render measured: seconds per phase, counts, memory. Written as report.json and
// summarised on stderr.
#include <chrono>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/progress.h"

namespace lvox {

struct Report {
  std::map<std::string, double> times;  // seconds; "total" is the whole command
  // CPU seconds of this process (all its threads) per phase of `times` a PhaseTimer
  // measured: the work itself, apart from waiting for cores on a shared machine (over MPI,
  // a rank's busy-polling waits in an exchange count as CPU).
  std::map<std::string, double> cpuTimes;
  std::map<std::string, uint64_t> counts;  // surfels, lvoxels, camera_rays, medium_evals, ...
  std::map<std::string, uint64_t> memory;  // bytes
  std::map<std::string, std::string> settings;
  std::vector<std::string> warnings;
  // Units of the work phase 1 splits over ranks that this process did (surfels sampled and
  // probed, triangles, lvoxel cells lit, ...): in one process the whole, over ranks each
  // rank's share, reported under "ranks" (docs/cluster.md).
  std::map<std::string, uint64_t> work;
  // A run split over ranks: each rank's host, times and work (null in one process).
  nlohmann::json perRank;

  void add(const std::string& count, uint64_t n) { counts[count] += n; }
  // A count, 0 when nothing was counted under that name.
  uint64_t count(const std::string& name) const {
    auto it = counts.find(name);
    return it == counts.end() ? 0 : it->second;
  }
  nlohmann::json toJson() const;
};

// Peak resident set size of this process, in bytes.
uint64_t peakRssBytes();
// CPU seconds this process has used so far (user + system, every thread).
double processCpuSeconds();

// Adds the seconds between construction and destruction to report.times[phase] (and the
// process's CPU seconds to report.cpuTimes[phase]), and
// records the process's peak RSS at the phase's end as memory["peak_rss_after_" + phase]:
// the first phase whose figure jumps is the one that allocated the peak.
class PhaseTimer {
 public:
  PhaseTimer(Report& report, std::string phase)
      : report_(report),
        phase_(std::move(phase)),
        start_(std::chrono::steady_clock::now()),
        cpuStart_(processCpuSeconds()) {
    Progress::global().beginPhase(phase_);
  }
  ~PhaseTimer() {
    Progress::global().endPhase();
    report_.times[phase_] +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    report_.cpuTimes[phase_] += processCpuSeconds() - cpuStart_;
    report_.memory["peak_rss_after_" + phase_] = peakRssBytes();
  }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

 private:
  Report& report_;
  std::string phase_;
  std::chrono::steady_clock::time_point start_;
  double cpuStart_;
};

}  // namespace lvox
