#include "src/app/report_inputs.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "src/core/error.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> splitCells(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

// A number, or the words strtod accepts for non-finite values as strings (JSON has no
// infinity); throws when the cell is not a number at all.
nlohmann::json numberCell(const std::string& cell, const std::string& path, size_t line,
                          const std::string& column) {
  char* end = nullptr;
  const double v = std::strtod(cell.c_str(), &end);
  if (cell.empty() || end != cell.c_str() + cell.size())
    throw InputError(path, "line " + std::to_string(line) + ": " + column,
                     "is not a number: '" + cell + "'");
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return v;
}

std::ifstream openText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", std::string("cannot open: ") + std::strerror(errno));
  return in;
}

void stripCr(std::string& line) {
  if (!line.empty() && line.back() == '\r') line.pop_back();
}

// The directory's name, also for "dir/" and "dir/.".
std::string directoryName(const std::string& dir) {
  fs::path p = fs::path(dir).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p.filename().empty() ? dir : p.filename().string();
}

nlohmann::json numberGroup(const nlohmann::json& j, const std::string& group,
                           const std::string& path) {
  if (!j.contains(group)) return nlohmann::json::object();
  if (!j[group].is_object()) throw InputError(path, group, "is not an object");
  for (const auto& [key, value] : j[group].items())
    if (!value.is_number() || !std::isfinite(value.get<double>()))
      throw InputError(path, group + "." + key, "is not a finite number");
  return j[group];
}

}  // namespace

nlohmann::json readCsvTable(const std::string& path, const std::vector<std::string>& required,
                            const std::vector<std::string>& textColumns) {
  std::ifstream in = openText(path);
  std::string line;
  if (!std::getline(in, line)) throw InputError(path, "", "is empty (no CSV header)");
  stripCr(line);
  const std::vector<std::string> columns = splitCells(line);
  for (const std::string& r : required)
    if (std::find(columns.begin(), columns.end(), r) == columns.end())
      throw InputError(path, r, "column missing from the CSV header");
  nlohmann::json rows = nlohmann::json::array();
  for (size_t number = 2; std::getline(in, line); ++number) {
    stripCr(line);
    if (line.empty()) continue;
    const std::vector<std::string> cells = splitCells(line);
    if (cells.size() != columns.size())
      throw InputError(path, "line " + std::to_string(number),
                       "has " + std::to_string(cells.size()) + " cells, the header " +
                           std::to_string(columns.size()));
    nlohmann::json row = nlohmann::json::object();
    for (size_t c = 0; c < columns.size(); ++c) {
      const bool text =
          std::find(textColumns.begin(), textColumns.end(), columns[c]) != textColumns.end();
      row[columns[c]] =
          text ? nlohmann::json(cells[c]) : numberCell(cells[c], path, number, columns[c]);
    }
    rows.push_back(std::move(row));
  }
  if (rows.empty()) throw InputError(path, "", "has a header but no rows");
  return {{"columns", columns}, {"rows", rows}};
}

nlohmann::json readSweepCsv(const std::string& dir) {
  if (!fs::is_directory(dir)) throw InputError(dir, "--sweep", "is not a directory");
  const std::string csv = (fs::path(dir) / "sweep.csv").string();
  if (!fs::exists(csv))
    throw InputError(dir, "--sweep", "has no sweep.csv (not an `lvox sweep` directory)");
  nlohmann::json t = readCsvTable(
      csv, {"method", "parameter", "value", "seconds", "medium_evals", "delta_percent"},
      {"scene", "mode", "method", "parameter"});
  t["name"] = directoryName(dir);
  t["path"] = dir;
  return t;
}

nlohmann::json readConvergenceCsv(const std::string& path) {
  nlohmann::json t = readCsvTable(path, {"spp", "seconds", "delta_percent"}, {});
  t["name"] = fs::path(path).filename().string();
  t["path"] = path;
  return t;
}

nlohmann::json readRenderReport(const std::string& path) {
  std::ifstream in = openText(path);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, "", std::string("is not JSON: ") + e.what());
  }
  if (!j.is_object()) throw InputError(path, "", "is not a JSON object");
  if (!j.contains("times") && !j.contains("counts") && !j.contains("memory"))
    throw InputError(path, "", "is not an lvox render report (no times, counts or memory)");
  nlohmann::json out = {{"path", path}, {"name", fs::path(path).filename().string()}};
  for (const char* group : {"times", "counts", "memory"}) out[group] = numberGroup(j, group, path);
  out["settings"] = nlohmann::json::object();
  if (j.contains("settings")) {
    if (!j["settings"].is_object()) throw InputError(path, "settings", "is not an object");
    for (const auto& [key, value] : j["settings"].items())
      out["settings"][key] = value.is_string() ? value.get<std::string>() : value.dump();
  }
  out["warnings"] = nlohmann::json::array();
  if (j.contains("warnings")) {
    if (!j["warnings"].is_array()) throw InputError(path, "warnings", "is not an array");
    for (const auto& w : j["warnings"])
      out["warnings"].push_back(w.is_string() ? w.get<std::string>() : w.dump());
  }
  return out;
}

std::vector<std::string> shortNames(const std::vector<std::string>& paths) {
  std::vector<std::string> names;
  std::set<std::string> seen, repeated;
  for (const std::string& p : paths) {
    names.push_back(fs::path(p).filename().string());
    if (!seen.insert(names.back()).second) repeated.insert(names.back());
  }
  for (size_t i = 0; i < names.size(); ++i)
    if (repeated.count(names[i]) || names[i].empty()) names[i] = paths[i];
  return names;
}

}  // namespace lvox
