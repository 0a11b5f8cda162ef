#pragma once
// Runs lvox under `mpirun -np N` (OpenMPI), as the tests of a render split over ranks do.
// Built with MPI, CMake gives the launcher's path as LVOX_MPIRUN; without it the tests
// that need it skip, saying why.
#include <unistd.h>

#include <string>

#include "app/run_lvox.h"

namespace lvox::test {

inline bool haveMpirun() {
#ifdef LVOX_MPIRUN
  return true;
#else
  return false;
#endif
}

// `mpirun -np N` with what this machine needs: more ranks than cores (--oversubscribe),
// root in CI containers (--allow-run-as-root), and no cross-memory attach between ranks,
// which containers often forbid (vader's single-copy mechanism).
inline std::string mpirunPrefix(int ranks) {
#ifdef LVOX_MPIRUN
  std::string cmd = std::string(LVOX_MPIRUN) + " -np " + std::to_string(ranks) +
                    " --oversubscribe --mca btl_vader_single_copy_mechanism none";
  if (geteuid() == 0) cmd += " --allow-run-as-root";
  return cmd + " ";
#else
  (void)ranks;
  return {};
#endif
}

// Runs `mpirun -np N lvox ARGS`, stderr captured (mpirun's own messages included).
inline RunResult runLvoxRanks(int ranks, const std::string& args,
                              const std::filesystem::path& dir) {
  const std::filesystem::path errFile = dir / "stderr.txt";
  const std::string cmd = mpirunPrefix(ranks) + LVOX_BINARY + " " + args + " >/dev/null 2>" +
                          errFile.string() + " </dev/null";
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

}  // namespace lvox::test
