#include "src/app/report_images.h"

#include <cmath>
#include <filesystem>

#include "src/app/base64.h"
#include "src/app/report_inputs.h"
#include "src/app/sweep_images.h"
#include "src/core/error.h"
#include "src/core/exr_channels.h"
#include "src/core/image_metrics.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

// Box filter by an integer factor; edge blocks average the pixels they have.
std::vector<float> downsample(const std::vector<float>& plane, int width, int height, int f) {
  if (f == 1) return plane;
  const int w = (width + f - 1) / f, h = (height + f - 1) / f;
  std::vector<float> out(static_cast<size_t>(w) * static_cast<size_t>(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double sum = 0.0;
      int n = 0;
      for (int yy = y * f; yy < std::min(height, (y + 1) * f); ++yy)
        for (int xx = x * f; xx < std::min(width, (x + 1) * f); ++xx, ++n)
          sum +=
              plane[static_cast<size_t>(yy) * static_cast<size_t>(width) + static_cast<size_t>(xx)];
      out[static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)] =
          static_cast<float>(sum / n);
    }
  return out;
}

long long pixelsAt(const std::vector<ExrChannels>& all, int f) {
  long long total = 0;
  for (const ExrChannels& c : all)
    total += static_cast<long long>((c.width + f - 1) / f) * ((c.height + f - 1) / f);
  return total;
}

nlohmann::json finiteOrText(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(v > 0 ? "inf" : "nan");
}

nlohmann::json metricsJson(const ImageError& e) {
  return {{"delta_percent", finiteOrText(e.deltaPercent)},
          {"relmse", finiteOrText(e.relMse)},
          {"rmse", finiteOrText(e.rmse)},
          {"psnr_db", finiteOrText(e.psnrDb)},
          {"max_abs", finiteOrText(e.maxAbs)},
          {"mean_ratio", finiteOrText(e.meanRatio)}};
}

nlohmann::json layersJson(const std::vector<std::string>& names) {
  nlohmann::json layers = nlohmann::json::array();
  for (const std::string& n : names) {
    const std::string layer = channelLayer(n);
    if (layers.empty() || layers.back()["name"] != layer)
      layers.push_back({{"name", layer}, {"channels", nlohmann::json::array()}});
    layers.back()["channels"].push_back(n);
  }
  return layers;
}

nlohmann::json imageJson(const std::string& path, const std::string& name, const ExrChannels& c,
                         int factor) {
  nlohmann::json planes = nlohmann::json::object();
  for (size_t i = 0; i < c.names.size(); ++i)
    planes[c.names[i]] = base64Floats(downsample(c.planes[i], c.width, c.height, factor));
  return {{"name", name},
          {"path", path},
          {"width", (c.width + factor - 1) / factor},
          {"height", (c.height + factor - 1) / factor},
          {"source_width", c.width},
          {"source_height", c.height},
          {"scale", factor},
          {"layers", layersJson(c.names)},
          {"channels", planes},
          {"metadata", c.metadata},
          {"metrics", nullptr}};
}

int downsampleFactor(const std::vector<ExrChannels>& all, std::vector<std::string>& notes) {
  int f = 1;
  while (pixelsAt(all, f) > kReportMaxPixels) ++f;
  if (f > 1)
    notes.push_back("The images hold " + std::to_string(pixelsAt(all, 1)) +
                    " pixels in all, more than " + std::to_string(kReportMaxPixels) +
                    ": the viewer shows them downsampled 1:" + std::to_string(f) +
                    " (box filter), error maps included. The error table is of the full images.");
  return f;
}

}  // namespace

nlohmann::json reportImages(const std::vector<std::string>& images, const std::string& reference,
                            std::vector<std::string>& notes) {
  std::vector<std::string> paths = images;
  if (!reference.empty()) paths.push_back(reference);
  std::vector<ExrChannels> all;
  for (const std::string& p : paths) all.push_back(readExrChannels(p));
  std::optional<Image> ref;
  if (!reference.empty()) {
    ref = colourImage(all.back());
    if (!ref) throw InputError(reference, "--reference", "has neither R, G, B nor Y channels");
  }
  const int factor = downsampleFactor(all, notes);
  const std::vector<std::string> names = shortNames(paths);
  nlohmann::json out = {{"images", nlohmann::json::array()}, {"reference", nullptr}};
  for (size_t i = 0; i < paths.size(); ++i) {
    nlohmann::json j = imageJson(paths[i], names[i], all[i], factor);
    const bool isReference = ref && i + 1 == paths.size();
    j["role"] = isReference ? "reference" : "image";
    if (ref && !isReference)
      if (const std::optional<Image> colour = colourImage(all[i]))
        j["metrics"] = metricsJson(compareImages(*colour, *ref, paths[i], reference));
    out["images"].push_back(std::move(j));
  }
  if (ref) out["reference"] = paths.size() - 1;
  return out;
}

nlohmann::json sweepThumbnails(const std::string& dir, size_t rows) {
  if (!fs::is_directory(fs::path(dir) / kSweepPointsFolder)) return nullptr;
  nlohmann::json out = {{"reference", nullptr}, {"points", nlohmann::json::array()}};
  int width = 0, height = 0;
  // Every point of one sweep has the camera's size: the first one fixes the thumbnails'.
  auto thumbnail = [&](const std::string& path) {
    const ExrChannels c = readExrChannels(path);
    const std::optional<Image> colour = colourImage(c);
    if (!colour) throw InputError(path, "", "has neither R, G, B nor Y channels");
    if (width == 0) {
      width = c.width;
      height = c.height;
    } else if (c.width != width || c.height != height) {
      throw InputError(path, "", "has another size than the other images of the sweep");
    }
    const int f = std::max(1, static_cast<int>(std::ceil(std::max(c.width, c.height) / 64.0)));
    nlohmann::json t = {{"rgb", nlohmann::json::array()}, {"error", nullptr}};
    for (const char* ch : {"R", "G", "B"}) {
      const std::vector<float>* p = c.find(ch) ? c.find(ch) : c.find("Y");
      t["rgb"].push_back(base64Floats(downsample(*p, c.width, c.height, f)));
    }
    if (const std::vector<float>* e = c.find(kSweepErrorChannel))
      t["error"] = base64Floats(downsample(*e, c.width, c.height, f));
    out["width"] = (c.width + f - 1) / f;
    out["height"] = (c.height + f - 1) / f;
    return t;
  };
  const fs::path ref = fs::path(dir) / kSweepReferenceFile;
  if (fs::exists(ref)) out["reference"] = thumbnail(ref.string());
  for (size_t i = 0; i < rows; ++i) {
    const std::optional<std::string> file = findSweepPoint(dir, i);
    out["points"].push_back(file ? thumbnail(*file) : nlohmann::json(nullptr));
  }
  if (width == 0) return nullptr;
  return out;
}

}  // namespace lvox
