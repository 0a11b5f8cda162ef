#pragma once
// What the environment says about how this process was started: MPI launchers (OpenMPI's
// mpirun, Slurm's srun with PMI/PMIx) tell every process its rank and the job's size in
// environment variables before MPI is initialised.
#include <optional>
#include <string>

namespace lvox {

struct LaunchedRank {
  int rank = 0;
  std::optional<int> size;  // unknown when the launcher names only the rank (PMIx)
  std::string variable;     // the environment variable that told
};

// The rank an MPI launcher gave this process, or nothing when none started it.
std::optional<LaunchedRank> launchedRank();

// True when the launcher started more than this one process.
bool launchedWithOthers(const LaunchedRank& launched);

}  // namespace lvox
