#pragma once
// Runs the lvox executable with arguments, capturing its exit code and stderr.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace lvox {

struct RunResult {
  int exitCode = -1;
  std::string err;
};

inline RunResult runLvox(const std::string& args, const std::filesystem::path& dir) {
  const std::filesystem::path errFile = dir / "stderr.txt";
  const std::string cmd =
      std::string(LVOX_BINARY) + " " + args + " >/dev/null 2>" + errFile.string();
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(errFile);
  std::ostringstream s;
  s << in.rdbuf();
  r.err = s.str();
  std::filesystem::remove(errFile);
  return r;
}

}  // namespace lvox
