#include "src/render/report.h"

#include <sys/resource.h>
#include <time.h>

namespace lvox {

nlohmann::json Report::toJson() const {
  nlohmann::json j;
  j["times"] = times;
  if (!cpuTimes.empty()) j["cpu_times"] = cpuTimes;
  j["counts"] = counts;
  j["memory"] = memory;
  j["settings"] = settings;
  j["warnings"] = warnings;
  if (!work.empty()) j["work"] = work;
  if (!perRank.is_null()) j["ranks"] = perRank;
  return j;
}

uint64_t peakRssBytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<uint64_t>(usage.ru_maxrss) * 1024u;  // Linux reports KiB
}

double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace lvox
