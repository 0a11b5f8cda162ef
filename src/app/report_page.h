#pragma once
// `lvox report`'s page: one self-contained HTML file (no network, no server) made of the
// page's own HTML, CSS and scripts (src/app/report/, compiled in) and the data of the
// inputs as JSON, HDR pixels included.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lvox {

struct ReportInputs {
  std::string title = "lvox report";
  std::string reference;                 // EXR, may be empty
  std::vector<std::string> images;       // EXRs
  std::vector<std::string> sweeps;       // directories of `lvox sweep`
  std::vector<std::string> convergence;  // CSVs of `lvox render --convergence-csv`
  std::vector<std::string> reports;      // JSONs of `lvox render --report`
};

// Reads and validates every input (InputError on the first bad one) into the page's data.
nlohmann::json reportData(const ReportInputs& inputs);

// The page around `data`.
std::string reportHtml(const nlohmann::json& data, const std::string& title);

// Validates everything, then publishes the page atomically at `path` (an .html file that
// is none of the inputs).
void writeReport(const std::string& path, const ReportInputs& inputs);

}  // namespace lvox
