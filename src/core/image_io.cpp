#include "src/core/image_io.h"

#include <Imath/half.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <OpenImageIO/imageio.h>
#include <png.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "src/core/atomic_file.h"
#include "src/core/error.h"
#include "src/core/exr_input.h"
#include "src/core/exr_precheck.h"

namespace lvox {
namespace {

constexpr float kHalfMax = 65504.0f;

std::string shortMessage(const std::exception& e) {
  std::string s = e.what();
  if (s.size() > 200) s = s.substr(0, 200) + "...";
  return s;
}

void checkSize(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<size_t>(image.width) * image.height)
    throw InputError(path, "", "image has an invalid size");
}

// Verifies a written EXR by reading its header and checking completeness and size.
void verifyExr(const std::string& tmp, int width, int height) {
  Imf::InputFile in(tmp.c_str());
  const Imath::Box2i dw = in.header().dataWindow();
  if (!in.isComplete() || dw.max.x - dw.min.x + 1 != width || dw.max.y - dw.min.y + 1 != height)
    throw std::runtime_error("the written EXR does not read back complete");
}

}  // namespace

namespace {

// A channel's values as written: non-finite (and, for colour, negative) values become 0,
// values beyond the half-float range are clamped when writing half.
std::vector<float> sanitizedChannel(std::vector<float> values, bool allowNegative, bool half,
                                    ExrWriteStats& stats) {
  for (float& v : values) {
    if (!std::isfinite(v) || (!allowNegative && v < 0.0f)) {
      v = 0.0f;
      ++stats.sanitized;
    }
    if (half && std::abs(v) > kHalfMax) {
      v = std::copysign(kHalfMax, v);
      ++stats.clamped;
    }
  }
  return values;
}

}  // namespace

ExrWriteStats writeExr(const std::string& path, const Image& image, bool half,
                       const ImageMetadata& metadata, OutputSet* set,
                       const std::vector<ExtraChannel>& extra) {
  checkSize(path, image);
  ExrWriteStats stats;
  const size_t n = image.pixels.size();
  std::vector<std::string> names = {"R", "G", "B"};
  std::vector<std::vector<float>> channels;
  for (int c = 0; c < 3; ++c) {
    std::vector<float> plane(n);
    for (size_t i = 0; i < n; ++i) plane[i] = image.pixels[i][c];
    channels.push_back(sanitizedChannel(std::move(plane), false, half, stats));
  }
  for (const ExtraChannel& e : extra) {
    if (e.values.size() != n) throw InputError(path, e.name, "channel has the wrong size");
    names.push_back(e.name);
    channels.push_back(sanitizedChannel(e.values, true, half, stats));
  }
  std::vector<std::vector<Imath::half>> halves;
  if (half)
    for (const std::vector<float>& c : channels) halves.emplace_back(c.begin(), c.end());

  auto write = [&](const std::string& tmp) {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const auto& [key, value] : metadata) header.insert(key, Imf::StringAttribute(value));
    const Imf::PixelType type = half ? Imf::HALF : Imf::FLOAT;
    const size_t size = half ? sizeof(Imath::half) : sizeof(float);
    Imf::FrameBuffer fb;
    for (size_t c = 0; c < names.size(); ++c) {
      header.channels().insert(names[c], Imf::Channel(type));
      char* base = half ? reinterpret_cast<char*>(halves[c].data())
                        : reinterpret_cast<char*>(channels[c].data());
      fb.insert(names[c], Imf::Slice(type, base, size, size * static_cast<size_t>(image.width)));
    }
    // The OutputFile is destroyed (and so finished) before the file is verified and renamed.
    Imf::OutputFile out(tmp.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(image.height);
  };
  auto verify = [&](const std::string& tmp) { verifyExr(tmp, image.width, image.height); };
  if (set)
    set->stage(path, write, verify);
  else
    publishAtomically(path, write, verify);
  return stats;
}

Image readExr(const std::string& path, ImageMetadata* metadata) {
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw InputError(path, "", std::string("cannot open: ") + std::strerror(errno));
  }
  // OpenEXR allocates what the header's sizes say: check them against the file first.
  precheckExrFile(path);
  try {
    Imf::InputFile in(path.c_str());
    const ExrSize size = checkedExrSize(path, in);
    const Imath::Box2i& dw = size.window;
    const long long w = size.width, h = size.height;
    const Imf::ChannelList& list = in.header().channels();
    const bool rgb = list.findChannel("R") && list.findChannel("G") && list.findChannel("B");
    const bool grey = list.findChannel("Y") != nullptr;
    if (!rgb && !grey) throw InputError(path, "", "the EXR has neither R, G, B nor Y channels");
    Image image;
    image.width = static_cast<int>(w);
    image.height = static_cast<int>(h);
    // Rows are decoded a strip at a time and the image grows with what was decoded, so a
    // small corrupt file that declares a huge data window fails on its first strip instead
    // of first allocating gigabytes (found by fuzzing).
    image.pixels.reserve(static_cast<size_t>(std::min(w * h, 1ll << 22)));
    const long long stripRows = std::clamp((1ll << 20) / w, 1ll, h);
    std::vector<float> planes[3];
    const char* names[3] = {"R", "G", "B"};
    const size_t xStride = sizeof(float), yStride = sizeof(float) * static_cast<size_t>(w);
    for (long long y0 = 0; y0 < h; y0 += stripRows) {
      const long long rows = std::min(stripRows, h - y0);
      const size_t n = static_cast<size_t>(w * rows);
      const long long firstRow = dw.min.y + y0;
      Imf::FrameBuffer fb;
      for (int c = 0; c < 3; ++c) {
        planes[c].assign(n, 0.0f);
        // Offset the base so that pixel (dw.min.x, firstRow) lands at index 0.
        char* base = reinterpret_cast<char*>(planes[c].data()) -
                     static_cast<ptrdiff_t>(dw.min.x) * static_cast<ptrdiff_t>(xStride) -
                     static_cast<ptrdiff_t>(firstRow) * static_cast<ptrdiff_t>(yStride);
        fb.insert(rgb ? names[c] : "Y", Imf::Slice(Imf::FLOAT, base, xStride, yStride));
        if (!rgb) break;
      }
      in.setFrameBuffer(fb);
      in.readPixels(static_cast<int>(firstRow), static_cast<int>(firstRow + rows - 1));
      for (size_t i = 0; i < n; ++i)
        image.pixels.push_back(rgb ? RGB(planes[0][i], planes[1][i], planes[2][i])
                                   : RGB(planes[0][i], planes[0][i], planes[0][i]));
    }
    if (metadata) {
      for (auto it = in.header().begin(); it != in.header().end(); ++it)
        if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
          (*metadata)[it.name()] = s->value();
    }
    return image;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path, "", "not a readable OpenEXR file: " + shortMessage(e));
  }
}

Image readAnyImage(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".exr") return readExr(path);
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw InputError(path, "", std::string("cannot open: ") + std::strerror(errno));
    // An EXR by its magic number, whatever its name: OpenImageIO's EXR reader would hand it
    // to OpenEXR unchecked, which allocates what the header's sizes say (found by fuzzing:
    // 1.8 GB for a 392-byte file); readExr checks the header first.
    const unsigned char exrMagic[4] = {0x76, 0x2f, 0x31, 0x01};
    unsigned char magic[4] = {};
    probe.read(reinterpret_cast<char*>(magic), 4);
    if (probe.gcount() == 4 && std::memcmp(magic, exrMagic, 4) == 0) return readExr(path);
  }
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string msg = OIIO::geterror();
    msg = msg.substr(0, msg.find('\n'));
    throw InputError(path, "", "not a readable image: " + msg);
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 ||
      static_cast<long long>(spec.width) * spec.height > (1ll << 28))
    throw InputError(path, "", "image has an invalid size");
  const int channels = spec.nchannels;
  std::vector<float> pixels(static_cast<size_t>(spec.width) * spec.height * channels);
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data()))
    throw InputError(path, "", "cannot read the image's pixels");
  Image image(spec.width, spec.height);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    const float* p = &pixels[i * static_cast<size_t>(channels)];
    image.pixels[i] = channels >= 3 ? RGB(p[0], p[1], p[2]) : RGB(p[0]);
  }
  return image;
}

uint8_t toneMap(float linear, float exposure) {
  if (!std::isfinite(linear) || linear <= 0.0f) return 0;
  const float mapped = 1.0f - std::exp(-exposure * linear);
  const float srgb =
      mapped <= 0.0031308f ? 12.92f * mapped : 1.055f * std::pow(mapped, 1.0f / 2.4f) - 0.055f;
  return static_cast<uint8_t>(std::lround(std::clamp(srgb, 0.0f, 1.0f) * 255.0f));
}

void writePngRgb8(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb,
                  OutputSet* set) {
  if (width <= 0 || height <= 0 || rgb.size() != static_cast<size_t>(width) * height * 3)
    throw InputError(path, "", "PNG buffer has an invalid size");
  auto write = [&](const std::string& tmp) {
    png_image png;
    std::memset(&png, 0, sizeof(png));
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(width);
    png.height = static_cast<png_uint_32>(height);
    png.format = PNG_FORMAT_RGB;
    if (!png_image_write_to_file(&png, tmp.c_str(), 0, rgb.data(), 0, nullptr))
      throw std::runtime_error(std::string("libpng: ") + png.message);
  };
  if (set)
    set->stage(path, write);
  else
    publishAtomically(path, write);
}

void writePng(const std::string& path, const Image& image, float exposure, OutputSet* set) {
  checkSize(path, image);
  std::vector<uint8_t> rgb(image.pixels.size() * 3);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      rgb[3 * i + static_cast<size_t>(c)] = toneMap(image.pixels[i][c], exposure);
  writePngRgb8(path, image.width, image.height, rgb, set);
}

}  // namespace lvox
