#pragma once
// The files a render publishes: OUT.exr, its PNG preview and the optional report. They
// are checked before rendering (so a bad path fails fast) and each is written to a
// temporary file and renamed, so an interrupted or failed run loses nothing.
#include <functional>
#include <string>
#include <vector>

#include "src/core/atomic_file.h"
#include "src/core/image.h"
#include "src/core/image_io.h"
#include "src/render/report.h"

namespace lvox {

class RenderOutputs {
 public:
  // Throws InputError if the output is not an .exr path, its directory does not exist,
  // or any output would overwrite one of `inputs`.
  RenderOutputs(std::string exrPath, std::string reportPath, std::vector<std::string> inputs);

  // Stages the EXR (the image and its AOV `layers`), the PNG, the report and whatever
  // `extra` stages, then publishes them together: either all are in place or none is.
  void write(const Image& image, const std::vector<ExtraChannel>& layers, Report& report, bool half,
             const std::function<void(OutputSet&)>& extra = {}) const;
  // The PNG preview's exposure in stops (the EXR is never scaled): pixels x 2^stops before
  // the tone map. Throws InputError outside [-20, 20].
  void setPreviewExposure(double stops);
  const std::string& exrPath() const { return exr_; }
  const std::string& pngPath() const { return png_; }

 private:
  std::string exr_, png_, report_;
  std::vector<std::string> inputs_;
  float previewScale_ = 1.0f;
};

}  // namespace lvox
