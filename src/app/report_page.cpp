#include "src/app/report_page.h"

#include <filesystem>
#include <fstream>
#include <string_view>

#include "report_assets.h"
#include "src/app/report_images.h"
#include "src/app/report_inputs.h"
#include "src/app/sweep_images.h"
#include "src/core/atomic_file.h"
#include "src/core/error.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

std::string_view asset(std::string_view name) {
  for (const ReportAsset& a : kReportAssets)
    if (name == a.name) return a.text;
  throw std::logic_error("report asset missing: " + std::string(name));
}

void replaceAll(std::string& s, std::string_view from, std::string_view to) {
  for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
}

std::string escapeHtml(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

// JSON inside <script>: '<' only occurs in strings, where \u003c means the same, and
// without it no "</script>" or "<!--" in a file name can end the script early.
std::string scriptJson(const nlohmann::json& data) {
  std::string text = data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  replaceAll(text, "<", "\\u003c");
  return text;
}

// Every file the report reads, so that the output is checked against all of them.
std::vector<std::string> inputFiles(const ReportInputs& in) {
  std::vector<std::string> files = in.images;
  if (!in.reference.empty()) files.push_back(in.reference);
  files.insert(files.end(), in.convergence.begin(), in.convergence.end());
  files.insert(files.end(), in.reports.begin(), in.reports.end());
  for (const std::string& dir : in.sweeps) {
    files.push_back((fs::path(dir) / "sweep.csv").string());
    files.push_back((fs::path(dir) / kSweepReferenceFile).string());
  }
  return files;
}

}  // namespace

nlohmann::json reportData(const ReportInputs& in) {
  std::vector<std::string> notes;
  nlohmann::json data = reportImages(in.images, in.reference, notes);
  data["sweeps"] = nlohmann::json::array();
  for (const std::string& dir : in.sweeps) {
    nlohmann::json sweep = readSweepCsv(dir);
    sweep["thumbs"] = sweepThumbnails(dir, sweep["rows"].size());
    data["sweeps"].push_back(std::move(sweep));
  }
  data["convergence"] = nlohmann::json::array();
  const std::vector<std::string> curveNames = shortNames(in.convergence);
  for (size_t i = 0; i < in.convergence.size(); ++i) {
    data["convergence"].push_back(readConvergenceCsv(in.convergence[i]));
    data["convergence"].back()["name"] = curveNames[i];
  }
  data["reports"] = nlohmann::json::array();
  const std::vector<std::string> reportNames = shortNames(in.reports);
  for (size_t i = 0; i < in.reports.size(); ++i) {
    data["reports"].push_back(readRenderReport(in.reports[i]));
    data["reports"].back()["name"] = reportNames[i];
  }
  data["notes"] = notes;
  return data;
}

std::string reportHtml(const nlohmann::json& data, const std::string& title) {
  std::string page(asset("page.html"));
  replaceAll(page, "{{title}}", escapeHtml(title));
  replaceAll(page, "<!--lvox:style-->", "<style>\n" + std::string(asset("page.css")) + "</style>");
  replaceAll(
      page, "<!--lvox:data-->",
      "<script type=\"application/json\" id=\"lvox-data\">" + scriptJson(data) + "</script>");
  std::string scripts;
  for (const ReportAsset& a : kReportAssets)
    if (std::string_view(a.name).ends_with(".js"))
      scripts += "<script>\n// " + std::string(a.name) + "\n" + a.text + "</script>\n";
  replaceAll(page, "<!--lvox:scripts-->", scripts);
  return page;
}

void writeReport(const std::string& path, const ReportInputs& in) {
  if (fs::path(path).extension() != ".html")
    throw InputError(path, "--output", "must end in .html");
  if (in.images.empty() && in.reference.empty() && in.sweeps.empty() && in.convergence.empty() &&
      in.reports.empty())
    throw InputError(path, "--output",
                     "nothing to report: give images, --sweep, --convergence or --reports");
  checkOutputPath(path, "--output", inputFiles(in));
  const std::string page = reportHtml(reportData(in), in.title);
  publishAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << page;
    out.close();
    if (!out) throw std::runtime_error("cannot write the report");
  });
}

}  // namespace lvox
