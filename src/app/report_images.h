#pragma once
// The images of a report: every channel of each EXR as base64 float32, grouped into
// layers, with its error against the reference measured at full resolution; and the
// thumbnails of a sweep's points.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lvox {

// More pixels than this over all images and they are shown downsampled (the page says so).
inline constexpr long long kReportMaxPixels = 4'000'000;

// Reads `images` and `reference` (may be empty) into {"images": [...], "reference": index
// or null}; appends what the reader should know (downsampling) to `notes`. Throws
// InputError for unreadable files and for images of another size than the reference.
nlohmann::json reportImages(const std::vector<std::string>& images, const std::string& reference,
                            std::vector<std::string>& notes);

// Thumbnails of the points a sweep kept in DIR/points (and of DIR/reference.exr), at most
// `rows` points, as {"width", "height", "reference": {"rgb"} or null, "points": [{"rgb",
// "error"} or null]}; null when the sweep kept no images.
nlohmann::json sweepThumbnails(const std::string& dir, size_t rows);

}  // namespace lvox
