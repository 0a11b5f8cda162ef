#pragma once
// The tables `lvox report` reads besides images: sweep.csv of `lvox sweep`, the CSV of
// `lvox render --convergence-csv` and the JSON of `lvox render --report`. Each is
// validated and turned into the JSON the page reads; bad input throws InputError naming
// the file, the line or field, and what is wrong.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lvox {

// A CSV as lvox writes it (a header, no quoting). Cells of the text columns stay
// strings; every other cell must be a number (inf and nan are kept as strings).
// Returns {"columns": [...], "rows": [{column: value}, ...]}.
nlohmann::json readCsvTable(const std::string& path, const std::vector<std::string>& required,
                            const std::vector<std::string>& textColumns);

// DIR/sweep.csv as {"name", "path", "columns", "rows"}.
nlohmann::json readSweepCsv(const std::string& dir);

// A convergence CSV as {"name", "path", "columns", "rows"}.
nlohmann::json readConvergenceCsv(const std::string& path);

// A render report as {"name", "path", "times", "counts", "memory", "settings", "warnings"}.
nlohmann::json readRenderReport(const std::string& path);

// Short labels for files: the file names, or the paths as given when names repeat.
std::vector<std::string> shortNames(const std::vector<std::string>& paths);

}  // namespace lvox
