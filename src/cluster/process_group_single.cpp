// The process group of an lvox built without MPI: always one process.
#include <cstdlib>
#include <stdexcept>

#include "src/cluster/launcher.h"
#include "src/cluster/process_group.h"

namespace lvox {
namespace {

class AloneGroup final : public ProcessGroup {
 public:
  Collective& collective() override { return single_; }
  std::string describe() const override { return {}; }
  [[noreturn]] void abort(int code) override { std::exit(code); }

 private:
  SingleProcess single_;
};

}  // namespace

bool ProcessGroup::mpiBuilt() { return false; }

std::unique_ptr<ProcessGroup> ProcessGroup::join(int&, char**&) {
  if (const std::optional<LaunchedRank> launched = launchedRank();
      launched && launchedWithOthers(*launched))
    throw std::runtime_error(
        "an MPI launcher started this process as rank " + std::to_string(launched->rank) +
        (launched->size ? " of " + std::to_string(*launched->size) : std::string()) + " (" +
        launched->variable +
        "), but this lvox was built without MPI: install libopenmpi-dev and rebuild "
        "(.ci/setup), or run one process without mpirun/srun");
  return std::make_unique<AloneGroup>();
}

}  // namespace lvox
