#include "src/cluster/launcher.h"

#include <cstdlib>
#include <string>

namespace lvox {
namespace {

std::optional<int> intVariable(const char* name) {
  const char* text = std::getenv(name);
  if (!text || !*text) return std::nullopt;
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  if (*end != '\0' || value < 0 || value > 1 << 24) return std::nullopt;
  return static_cast<int>(value);
}

}  // namespace

std::optional<LaunchedRank> launchedRank() {
  // OpenMPI's mpirun, then PMI-1/PMI-2 (srun --mpi=pmi2, MPICH's launchers), then PMIx
  // (srun --mpi=pmix), which gives the rank only.
  struct Names {
    const char* rank;
    const char* size;
  };
  for (const Names& n : {Names{"OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE"},
                         Names{"PMI_RANK", "PMI_SIZE"}, Names{"PMIX_RANK", nullptr}}) {
    const std::optional<int> rank = intVariable(n.rank);
    if (!rank) continue;
    LaunchedRank launched;
    launched.rank = *rank;
    if (n.size) launched.size = intVariable(n.size);
    launched.variable = n.rank;
    return launched;
  }
  return std::nullopt;
}

bool launchedWithOthers(const LaunchedRank& launched) {
  return launched.rank > 0 || (launched.size && *launched.size > 1);
}

}  // namespace lvox
