// The process group of an lvox built with MPI: joins the MPI job when a launcher started
// this process, else stays alone without initialising MPI (plain runs and the test suite
// pay nothing for it).
#include <unistd.h>

#include <cstdlib>
#include <optional>

#include "src/cluster/launcher.h"
#include "src/cluster/mpi_collective.h"
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

class MpiGroup final : public ProcessGroup {
 public:
  MpiGroup(int& argc, char**& argv) {
    // Only the main thread calls MPI; TBB's workers never do.
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    collective_ = std::make_unique<MpiCollective>();
  }
  ~MpiGroup() override {
    collective_.reset();
    MPI_Finalize();
  }
  MpiGroup(const MpiGroup&) = delete;
  MpiGroup& operator=(const MpiGroup&) = delete;

  Collective& collective() override { return *collective_; }
  std::string describe() const override {
    char host[256] = {};
    gethostname(host, sizeof host - 1);
    return "rank " + std::to_string(collective_->rank()) + " of " +
           std::to_string(collective_->size()) + " on " + host;
  }
  [[noreturn]] void abort(int code) override {
    MPI_Abort(MPI_COMM_WORLD, code);
    std::exit(code);
  }

 private:
  std::unique_ptr<MpiCollective> collective_;
};

}  // namespace

bool ProcessGroup::mpiBuilt() { return true; }

std::unique_ptr<ProcessGroup> ProcessGroup::join(int& argc, char**& argv) {
  if (!launchedRank()) return std::make_unique<AloneGroup>();
  return std::make_unique<MpiGroup>(argc, argv);
}

}  // namespace lvox
