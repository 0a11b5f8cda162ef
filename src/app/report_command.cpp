// `lvox report -o REPORT.html [--reference REF.exr] [IMAGE.exr ...] [--sweep DIR ...]
// [--convergence CSV ...] [--reports R.json ...]`: one self-contained interactive page
// comparing renders (docs/report.md).
#include <iostream>
#include <memory>

#include "src/app/commands.h"
#include "src/app/report_page.h"

namespace lvox {
namespace {

struct ReportFlags {
  std::string output;
  bool quiet = false;
  ReportInputs inputs;
};

int runReport(const ReportFlags& f) {
  writeReport(f.output, f.inputs);
  if (!f.quiet) std::cerr << "lvox: wrote " << f.output << "\n";
  return 0;
}

}  // namespace

void addReportCommand(CLI::App& app, int& exitCode) {
  auto f = std::make_shared<ReportFlags>();
  CLI::App* cmd = app.add_subcommand(
      "report", "One self-contained HTML page comparing renders, sweeps and render reports");
  cmd->add_option("images", f->inputs.images, "Renders to compare (EXR, any layers)");
  cmd->add_option("-o,--output", f->output, "The page (.html)")->required();
  cmd->add_option("--reference", f->inputs.reference, "Reference EXR: error maps and metrics");
  cmd->add_option("--sweep", f->inputs.sweeps, "Directories written by lvox sweep");
  cmd->add_option("--convergence", f->inputs.convergence,
                  "CSVs written by lvox render --convergence-csv");
  cmd->add_option("--reports,--report", f->inputs.reports,
                  "JSON files written by lvox render --report");
  cmd->add_option("--title", f->inputs.title, "Title of the page");
  cmd->add_flag("-q,--quiet", f->quiet, "No summary line");
  cmd->callback([f, &exitCode]() { exitCode = runReport(*f); });
}

}  // namespace lvox
