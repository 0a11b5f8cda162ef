// `lvox compare A.exr B.exr [--json] [--heatmap H.png] [--layer NAME]`: error of A against
// reference B.
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "src/app/commands.h"
#include "src/core/atomic_file.h"
#include "src/core/error.h"
#include "src/core/exr_channels.h"
#include "src/core/image_io.h"
#include "src/core/image_metrics.h"

namespace lvox {
namespace {

struct CompareFlags {
  std::string test, reference, heatmap, layer;
  bool json = false;
};

// Relative error on a log scale, 1e-3 (dark blue) .. 1 and above (yellow), through a
// viridis-like ramp, so small and large errors are both readable.
std::array<uint8_t, 3> heatColour(float relativeError) {
  static constexpr float stops[5][3] = {
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  const float x =
      std::clamp((std::log10(std::max(relativeError, 1e-6f)) + 3.0f) / 3.0f, 0.0f, 1.0f);
  const float f = x * 4.0f;
  const int i = std::min(3, static_cast<int>(f));
  const float t = f - static_cast<float>(i);
  std::array<uint8_t, 3> c{};
  for (int k = 0; k < 3; ++k)
    c[static_cast<size_t>(k)] =
        static_cast<uint8_t>(std::lround(stops[i][k] * (1 - t) + stops[i + 1][k] * t));
  return c;
}

void writeHeatmap(const std::string& path, const Image& test, const Image& reference) {
  const std::vector<float> err = relativeErrorMap(test, reference);
  std::vector<uint8_t> rgb(err.size() * 3);
  for (size_t i = 0; i < err.size(); ++i) {
    const auto c = heatColour(err[i]);
    for (size_t k = 0; k < 3; ++k) rgb[3 * i + k] = c[k];
  }
  writePngRgb8(path, test.width, test.height, rgb);
}

// One layer of an EXR as an RGB image. A layer matches by its full name or by its last
// components (a Cycles file's "ViewLayer.Combined" matches "Combined"); its channels are
// R, G, B, or X, Y, Z, or one channel (Y, Z, V, ...) taken as grey. A missing or ambiguous
// layer throws InputError naming the layers the file has.
Image readLayer(const std::string& path, const std::string& layer) {
  const ExrChannels ch = readExrChannels(path);
  std::vector<std::string> layers;
  for (const auto& n : ch.names) {
    const std::string l = channelLayer(n);
    if (std::find(layers.begin(), layers.end(), l) == layers.end()) layers.push_back(l);
  }
  std::vector<std::string> matches;
  for (const auto& l : layers)
    if (l == layer || (l.size() > layer.size() && l.ends_with("." + layer))) matches.push_back(l);
  auto list = [&](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& l : v)
      s += (s.empty() ? "" : ", ") + (l.empty() ? std::string("(colour)") : l);
    return s;
  };
  if (std::find(matches.begin(), matches.end(), layer) != matches.end()) matches = {layer};
  if (matches.empty())
    throw InputError(path, "--layer", "no layer '" + layer + "'; the file has: " + list(layers));
  if (matches.size() > 1)
    throw InputError(path, "--layer", "layer '" + layer + "' is ambiguous: " + list(matches));
  const std::string prefix = matches[0].empty() ? "" : matches[0] + ".";
  std::vector<const std::vector<float>*> planes;
  for (const auto& trio : {std::array<const char*, 3>{"R", "G", "B"}, {"X", "Y", "Z"}}) {
    planes.clear();
    for (const char* c : trio)
      if (const auto* p = ch.find(prefix + c)) planes.push_back(p);
    if (planes.size() == 3) break;
  }
  if (planes.size() != 3) {
    planes.clear();
    for (const auto& n : ch.names)
      if (channelLayer(n) == matches[0]) planes.push_back(ch.find(n));
    if (planes.size() != 1)
      throw InputError(
          path, "--layer",
          "layer '" + matches[0] + "' has neither R, G, B nor X, Y, Z nor one channel");
    planes = {planes[0], planes[0], planes[0]};
  }
  Image image(ch.width, ch.height, RGB(0.0f));
  for (size_t i = 0; i < image.pixels.size(); ++i)
    image.pixels[i] = RGB((*planes[0])[i], (*planes[1])[i], (*planes[2])[i]);
  return image;
}

int runCompare(const CompareFlags& f) {
  if (!f.heatmap.empty()) {
    if (std::filesystem::path(f.heatmap).extension() != ".png")
      throw InputError(f.heatmap, "--heatmap", "must end in .png");
    checkOutputPath(f.heatmap, "--heatmap", {f.test, f.reference});
  }
  const Image test = f.layer.empty() ? readAnyImage(f.test) : readLayer(f.test, f.layer);
  const Image reference =
      f.layer.empty() ? readAnyImage(f.reference) : readLayer(f.reference, f.layer);
  const ImageError e = compareImages(test, reference, f.test, f.reference);
  if (!f.heatmap.empty()) writeHeatmap(f.heatmap, test, reference);
  if (f.json) {
    nlohmann::json j;
    j["delta_percent"] = e.deltaPercent;
    j["relmse"] = e.relMse;
    j["rmse"] = e.rmse;
    j["psnr_db"] = std::isfinite(e.psnrDb) ? nlohmann::json(e.psnrDb) : nlohmann::json("inf");
    j["max_abs"] = e.maxAbs;
    j["mean_ratio"] =
        std::isfinite(e.meanRatio) ? nlohmann::json(e.meanRatio) : nlohmann::json("inf");
    j["width"] = test.width;
    j["height"] = test.height;
    std::cout << j.dump(2) << "\n";
  } else {
    std::printf(
        "delta    %.4f %%\nrelMSE   %.6g\nRMSE     %.6g\nPSNR     %.3f dB\nmax abs  %.6g\n"
        "A/B mean %.6g\n",
        e.deltaPercent, e.relMse, e.rmse, e.psnrDb, e.maxAbs, e.meanRatio);
  }
  return 0;
}

}  // namespace

void addCompareCommand(CLI::App& app, int& exitCode) {
  auto flags = std::make_shared<CompareFlags>();
  CLI::App* cmd = app.add_subcommand("compare", "Error of image A against the reference B");
  cmd->add_option("test", flags->test, "Image to measure (EXR)")->required();
  cmd->add_option("reference", flags->reference, "Reference image (EXR)")->required();
  cmd->add_flag("--json", flags->json, "Print the metrics as JSON");
  cmd->add_option("--heatmap", flags->heatmap, "Write a false-colour relative-error PNG");
  cmd->add_option("--layer", flags->layer,
                  "Compare this EXR layer (e.g. albedo; Combined matches ViewLayer.Combined)");
  cmd->callback([flags, &exitCode]() { exitCode = runCompare(*flags); });
}

}  // namespace lvox
