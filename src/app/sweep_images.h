#pragma once
// What `lvox sweep` keeps beside sweep.csv so that its report can show the images: each
// point's render with its error map (DIR/points/NNN_METHOD_PARAMETER_VALUE.exr, the
// colour in R, G, B and the relative error against the reference in error.Y, NNN being
// the point's row in sweep.csv), the reference (DIR/reference.exr) and DIR/report.html.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "src/core/image.h"

namespace lvox {

inline constexpr const char* kSweepPointsFolder = "points";
inline constexpr const char* kSweepReferenceFile = "reference.exr";
inline constexpr const char* kSweepErrorChannel = "error.Y";
inline constexpr const char* kSweepReportFile = "report.html";

// The kept image of row `index` of DIR/sweep.csv, if there is one.
std::optional<std::string> findSweepPoint(const std::string& dir, size_t index);

class SweepKeeper {
 public:
  // Checks that nothing it will write is one of `inputs`; writes nothing yet.
  SweepKeeper(std::string dir, std::string givenReference, const std::vector<std::string>& inputs);

  // Starts a sweep: clears the point images of an earlier sweep into the same directory
  // (they would not match the new sweep.csv) and keeps the reference.
  void start(const Image& reference) const;
  void keepPoint(size_t index, const std::string& method, const std::string& parameter,
                 double value, const Image& image, const Image& reference) const;
  // DIR/report.html: the sweep's plots and thumbnails, and a viewer with the reference and
  // up to six points of the time Pareto front, given as (seconds, row) pairs.
  void publishReport(const std::string& title,
                     std::vector<std::pair<double, size_t>> frontByTime) const;

 private:
  std::string dir_, givenReference_, referencePath_;
};

}  // namespace lvox
