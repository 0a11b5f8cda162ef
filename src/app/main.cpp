// lvox: point-based global illumination with participating media.
#include <exception>
#include <iostream>
#include <memory>

#include "src/app/commands.h"
#include "src/app/version_info.h"
#include "src/cluster/process_group.h"

int main(int argc, char** argv) {
  // Started by mpirun or srun, lvox is one rank of several (docs/cluster.md).
  std::unique_ptr<lvox::ProcessGroup> group;
  try {
    group = lvox::ProcessGroup::join(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "lvox: error: " << e.what() << "\n";
    return 1;
  }
  lvox::Collective& team = group->collective();
  CLI::App app{"lvox: point-based global illumination with participating media"};
  app.require_subcommand(1);
  app.set_version_flag(
      "--version", lvox::versionLine() + (lvox::ProcessGroup::mpiBuilt() ? ", MPI" : ", no MPI"));
  int exitCode = 0;
  lvox::addRenderCommand(app, exitCode, team);
  lvox::addCompareCommand(app, exitCode);
  lvox::addMergeCommand(app, exitCode);
  lvox::addSweepCommand(app, exitCode, team);
  lvox::addReportCommand(app, exitCode);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version print and succeed; a usage error is one line, like every error.
    if (e.get_exit_code() == 0) return team.isRoot() ? app.exit(e) : 0;
    if (team.isRoot()) std::cerr << "lvox: error: " << e.what() << " (--help lists the options)\n";
    return 2;
  } catch (const std::exception& e) {
    if (!team.distributed()) {
      std::cerr << "lvox: error: " << e.what() << "\n";
      return 1;
    }
    // The other ranks may be waiting for this one in a collective call: end them all.
    std::cerr << "lvox: error: " << group->describe() << ": " << e.what() << "\n";
    group->abort(1);
  }
  return exitCode;
}
