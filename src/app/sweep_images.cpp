#include "src/app/sweep_images.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "src/app/report_page.h"
#include "src/core/atomic_file.h"
#include "src/core/exr_channels.h"
#include "src/core/image_io.h"
#include "src/core/image_metrics.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

std::string indexPrefix(size_t index) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%03zu_", index);
  return buf;
}

// Names the sweep's own files carry: NNN_ then anything, .exr.
bool isPointFile(const fs::path& p) {
  const std::string name = p.filename().string();
  const size_t digits = name.find('_');
  return p.extension() == ".exr" && digits >= 3 && digits != std::string::npos &&
         std::all_of(name.begin(), name.begin() + static_cast<ptrdiff_t>(digits),
                     [](char c) { return c >= '0' && c <= '9'; });
}

bool sameFile(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  return fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec);
}

ExrChannels pointChannels(const Image& image, const Image& reference) {
  ExrChannels c;
  c.width = image.width;
  c.height = image.height;
  c.names = {"R", "G", "B", kSweepErrorChannel};
  c.planes.assign(4, std::vector<float>(image.pixels.size()));
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int k = 0; k < 3; ++k) c.planes[static_cast<size_t>(k)][i] = image.pixels[i][k];
  c.planes[3] = relativeErrorMap(image, reference);
  return c;
}

// At most `n` entries spread evenly over the front, cheapest and most accurate included.
std::vector<size_t> spread(std::vector<std::pair<double, size_t>> front, size_t n) {
  std::sort(front.begin(), front.end());
  std::vector<size_t> rows;
  for (size_t k = 0; k < std::min(n, front.size()); ++k) {
    const size_t at = front.size() <= n ? k : (k * (front.size() - 1) + (n - 1) / 2) / (n - 1);
    rows.push_back(front[at].second);
  }
  return rows;
}

}  // namespace

std::optional<std::string> findSweepPoint(const std::string& dir, size_t index) {
  const fs::path folder = fs::path(dir) / kSweepPointsFolder;
  std::error_code ec;
  std::vector<std::string> found;
  for (const fs::directory_entry& e : fs::directory_iterator(folder, ec))
    if (isPointFile(e.path()) && e.path().filename().string().rfind(indexPrefix(index), 0) == 0)
      found.push_back(e.path().string());
  if (found.empty()) return std::nullopt;
  std::sort(found.begin(), found.end());  // deterministic if a stray duplicate exists
  return found.front();
}

SweepKeeper::SweepKeeper(std::string dir, std::string givenReference,
                         const std::vector<std::string>& inputs)
    : dir_(std::move(dir)), givenReference_(std::move(givenReference)) {
  referencePath_ = (fs::path(dir_) / kSweepReferenceFile).string();
  std::vector<std::string> all = inputs;
  if (!sameFile(referencePath_, givenReference_)) {
    checkOutputPath(referencePath_, "--output", all);
    if (!givenReference_.empty()) all.push_back(givenReference_);
  }
  checkOutputPath((fs::path(dir_) / kSweepReportFile).string(), "--output", all);
}

void SweepKeeper::start(const Image& reference) const {
  const fs::path folder = fs::path(dir_) / kSweepPointsFolder;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(folder, ec))
    if (isPointFile(e.path()) && !sameFile(e.path(), givenReference_)) fs::remove(e.path());
  fs::create_directories(folder);
  if (!sameFile(referencePath_, givenReference_)) writeExr(referencePath_, reference);
}

void SweepKeeper::keepPoint(size_t index, const std::string& method, const std::string& parameter,
                            double value, const Image& image, const Image& reference) const {
  std::ostringstream name;
  name << indexPrefix(index) << method << '_' << parameter << '_' << value << ".exr";
  ExrChannels c = pointChannels(image, reference);
  c.metadata = {{"lvox.method", method}, {"lvox.parameter", parameter}};
  writeExrChannels((fs::path(dir_) / kSweepPointsFolder / name.str()).string(), c);
}

void SweepKeeper::publishReport(const std::string& title,
                                std::vector<std::pair<double, size_t>> frontByTime) const {
  ReportInputs in;
  in.title = title;
  in.reference = referencePath_;
  for (size_t row : spread(std::move(frontByTime), 6))
    if (const std::optional<std::string> p = findSweepPoint(dir_, row)) in.images.push_back(*p);
  in.sweeps = {dir_};
  lvox::writeReport((fs::path(dir_) / kSweepReportFile).string(), in);
}

}  // namespace lvox
