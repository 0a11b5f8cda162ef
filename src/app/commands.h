#pragma once
// Each subcommand lives in its own file and registers itself on the top-level CLI11 app.
// A subcommand's callback stores its exit status in `exitCode`; input errors are thrown
// as exceptions and turned into one line on stderr by main. `render` and `sweep` split
// their work over the ranks of `team` when lvox runs under mpirun or srun.
#include <CLI/CLI.hpp>

#include "src/core/collective.h"

namespace lvox {

void addRenderCommand(CLI::App& app, int& exitCode, Collective& team);
void addCompareCommand(CLI::App& app, int& exitCode);
void addMergeCommand(CLI::App& app, int& exitCode);
void addSweepCommand(CLI::App& app, int& exitCode, Collective& team);
void addReportCommand(CLI::App& app, int& exitCode);

}  // namespace lvox
