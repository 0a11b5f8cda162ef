#include "src/app/rank_times.h"

#include <unistd.h>

#include <cstdio>

namespace lvox {

void collectRankTimes(Collective& team, Report& report) {
  if (!team.distributed()) return;
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  nlohmann::json mine;
  mine["rank"] = team.rank();
  mine["host"] = host;
  mine["times"] = report.times;
  mine["cpu_times"] = report.cpuTimes;
  mine["work"] = report.work;
  const std::vector<std::string> all = team.gather(mine.dump(), 0);
  if (!team.isRoot()) return;
  report.perRank = nlohmann::json::array();
  for (const std::string& text : all) report.perRank.push_back(nlohmann::json::parse(text));
}

void printRankTimes(const Report& report) {
  if (!report.perRank.is_array()) return;
  for (const nlohmann::json& rank : report.perRank) {
    std::string line;
    for (const auto& [phase, seconds] : rank["times"].items()) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s%s %.2f s", line.empty() ? "" : ", ", phase.c_str(),
                    seconds.get<double>());
      line += buf;
    }
    std::fprintf(stderr, "lvox: rank %d (%s): %s\n", rank["rank"].get<int>(),
                 rank["host"].get<std::string>().c_str(), line.c_str());
  }
}

}  // namespace lvox
