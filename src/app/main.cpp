// lvox: point-based global illumination with participating media.
#include <exception>
#include <iostream>

#include "src/app/commands.h"
#include "src/app/version_info.h"

int main(int argc, char** argv) {
  CLI::App app{"lvox: point-based global illumination with participating media"};
  app.require_subcommand(1);
  app.set_version_flag("--version", lvox::versionLine());
  int exitCode = 0;
  lvox::addRenderCommand(app, exitCode);
  lvox::addCompareCommand(app, exitCode);
  lvox::addMergeCommand(app, exitCode);
  lvox::addSweepCommand(app, exitCode);
  lvox::addReportCommand(app, exitCode);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version print and succeed; a usage error is one line, like every error.
    if (e.get_exit_code() == 0) return app.exit(e);
    std::cerr << "lvox: error: " << e.what() << " (--help lists the options)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "lvox: error: " << e.what() << "\n";
    return 1;
  }
  return exitCode;
}
