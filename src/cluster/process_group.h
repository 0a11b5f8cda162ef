#pragma once
// The processes one run of lvox is split over. Started by an MPI launcher (mpirun, srun),
// lvox joins the MPI job and the libraries get an MPI-backed Collective; started alone,
// it is one process and they get SingleProcess. MPI is an optional dependency: without it
// (process_group_single.cpp is built instead of process_group_mpi.cpp) a run that a
// launcher started as several ranks stops with a clear error instead of having every rank
// render the whole image and write the same files.
#include <memory>
#include <string>

#include "src/core/collective.h"

namespace lvox {

class ProcessGroup {
 public:
  // Joins the MPI job when a launcher started this process. Throws std::runtime_error
  // when it started several ranks and this lvox was built without MPI.
  static std::unique_ptr<ProcessGroup> join(int& argc, char**& argv);
  // Whether this lvox was built with MPI (for --version).
  static bool mpiBuilt();

  virtual ~ProcessGroup() = default;
  virtual Collective& collective() = 0;
  // "rank R of N on HOST" under MPI, empty alone: what error messages are prefixed with.
  virtual std::string describe() const = 0;
  // Ends every rank of the job with `code` after this one failed (MPI_Abort): the others
  // would otherwise wait for it forever in the next collective call.
  [[noreturn]] virtual void abort(int code) = 0;
};

}  // namespace lvox
