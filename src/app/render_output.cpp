#include "src/app/render_output.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include "src/core/atomic_file.h"
#include "src/core/error.h"
#include "src/core/image_io.h"

namespace lvox {

RenderOutputs::RenderOutputs(std::string exrPath, std::string reportPath,
                             std::vector<std::string> inputs)
    : exr_(std::move(exrPath)), report_(std::move(reportPath)), inputs_(std::move(inputs)) {
  const std::filesystem::path p(exr_);
  if (p.extension() != ".exr") throw InputError(exr_, "--output", "must end in .exr");
  png_ = std::filesystem::path(exr_).replace_extension(".png").string();
  checkOutputPath(exr_, "--output", inputs_);
  checkOutputPath(png_, "--output (preview)", inputs_);
  if (!report_.empty()) {
    checkOutputPath(report_, "--report", inputs_);
    if (std::filesystem::weakly_canonical(report_) == std::filesystem::weakly_canonical(exr_) ||
        std::filesystem::weakly_canonical(report_) == std::filesystem::weakly_canonical(png_))
      throw InputError(report_, "--report", "is the same file as the image output");
  }
}

void RenderOutputs::setPreviewExposure(double stops) {
  if (!(stops >= -20.0 && stops <= 20.0))
    throw InputError("--exposure", "", "must be a number of stops in [-20, 20]");
  previewScale_ = static_cast<float>(std::exp2(stops));
}

void RenderOutputs::write(const Image& image, const std::vector<ExtraChannel>& layers,
                          Report& report, bool half,
                          const std::function<void(OutputSet&)>& extra) const {
  OutputSet set;
  ImageMetadata meta;
  for (const auto& [key, value] : report.settings) meta["lvox." + key] = value;
  const ExrWriteStats stats = writeExr(exr_, image, half, meta, &set, layers);
  if (stats.sanitized)
    report.warnings.push_back(std::to_string(stats.sanitized) +
                              " NaN/Inf/negative values written as 0");
  if (stats.clamped)
    report.warnings.push_back(std::to_string(stats.clamped) +
                              " values above 65504 clamped in the half-float EXR");
  writePng(png_, image, previewScale_, &set);
  if (!report_.empty()) {
    const std::string text = report.toJson().dump(2) + "\n";
    set.stage(report_, [&](const std::string& tmp) {
      std::ofstream out(tmp, std::ios::binary);
      out << text;
      out.close();
      if (!out) throw std::runtime_error("cannot write the report");
    });
  }
  if (extra) extra(set);
  set.commit();
}

}  // namespace lvox
