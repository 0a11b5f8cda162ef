#pragma once
// Reading and writing images. Every writer publishes atomically (atomic_file.h) and never
// lets NaN, Inf or negative values into a file: they are written as 0 and counted.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "src/core/atomic_file.h"
#include "src/core/image.h"

namespace lvox {

using ImageMetadata = std::map<std::string, std::string>;

struct ExrWriteStats {
  uint64_t sanitized = 0;  // NaN/Inf/negative values written as 0
  uint64_t clamped = 0;    // values above the half-float maximum (half output only)
};

// One more channel of an EXR beside R, G, B: an AOV layer's ("direct.R", "depth.Z"), one
// value per pixel, top row first.
struct ExtraChannel {
  std::string name;
  std::vector<float> values;
};

// Linear RGB OpenEXR, ZIP-compressed (lossless). Float32 by default; `half` clamps values
// above 65504. Metadata become string attributes of the header (e.g. "lvox.spp").
// With `set`, the file is staged in it (published by its commit) instead of at once.
// `extra` channels are written in the same type; they may be negative (a normal), and
// NaN or infinite values among them are written as 0 and counted as sanitized.
ExrWriteStats writeExr(const std::string& path, const Image& image, bool half = false,
                       const ImageMetadata& metadata = {}, OutputSet* set = nullptr,
                       const std::vector<ExtraChannel>& extra = {});

// Reads R, G, B (or Y as grey) of an OpenEXR file; throws InputError on a missing,
// corrupt or incomplete file. String attributes are returned in `metadata`.
Image readExr(const std::string& path, ImageMetadata* metadata = nullptr);

// Any image OpenImageIO reads (PNG, HDR, TIFF, JPEG, ...; an .exr goes to readExr): its
// first three channels as R, G, B, or its one channel as grey, values as the file stores
// them (8-bit PNG as 0..1, no sRGB decoding). Throws InputError on an unreadable file.
Image readAnyImage(const std::string& path);

// The preview tone map: per channel 1 - exp(-exposure * x) (keeps hue for moderate values,
// compresses highlights smoothly, never clips), then the sRGB transfer curve, to 8 bits.
uint8_t toneMap(float linear, float exposure = 1.0f);

// Tone-mapped 8-bit sRGB PNG preview.
void writePng(const std::string& path, const Image& image, float exposure = 1.0f,
              OutputSet* set = nullptr);
// An 8-bit RGB buffer (width * height * 3, top row first) as PNG.
void writePngRgb8(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb,
                  OutputSet* set = nullptr);

}  // namespace lvox
