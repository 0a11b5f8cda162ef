#include "src/world/linear_texture_input.h"

#include <Imath/half.h>
#include <OpenImageIO/imagecache.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <mutex>
#include <vector>

namespace lvox {

float srgbToLinear(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

namespace {

// An ImageInput that reads the whole file through OpenImageIO's own reader, decodes it,
// and serves its scanlines as half floats. One subimage, one level: the TextureSystem makes
// the mip levels ("automip") from these linear values. The cache copies the image as it
// reads it, so the decoded pixels are let go once the last row is served, and decoded again
// should the cache come back for rows it let go of.
class LinearTextureInput final : public OIIO::ImageInput {
 public:
  const char* format_name() const override { return "lvox-linear"; }

  bool open(const std::string& name, OIIO::ImageSpec& newspec) override {
    name_ = name;
    if (!decode()) return false;
    newspec = m_spec;
    return true;
  }

  bool close() override {
    const std::lock_guard<std::mutex> guard(mutex_);
    release();
    return true;
  }

  bool read_native_scanline(int subimage, int miplevel, int y, int /*z*/, void* data) override {
    const int row = y - m_spec.y;
    if (subimage != 0 || miplevel != 0 || row < 0 || row >= m_spec.height) return false;
    const std::lock_guard<std::mutex> guard(mutex_);
    if (pixels_.empty() && !decode()) return false;
    std::memcpy(data, reinterpret_cast<const char*>(pixels_.data()) + rowBytes_ * row, rowBytes_);
    if (row == m_spec.height - 1) release();
    return true;
  }

 private:
  void release() {
    pixels_.clear();
    pixels_.shrink_to_fit();
  }

  bool decode() {
    auto in = OIIO::ImageInput::open(name_);
    if (!in) {
      errorf("%s", OIIO::geterror());
      return false;
    }
    OIIO::ImageSpec spec = in->spec();
    if (spec.depth > 1 || spec.nchannels < 1) {
      errorf("%s: not a flat image", name_);
      return false;
    }
    const size_t values = spec.image_pixels() * static_cast<size_t>(spec.nchannels);
    std::vector<float> decoded(values);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeFloat, decoded.data())) {
      errorf("%s", in->geterror());
      return false;
    }
    const bool encoded = !spec.format.is_floating_point();
    pixels_.resize(values);
    const auto channels = static_cast<size_t>(spec.nchannels);
    for (size_t i = 0; i < values; ++i) {
      const bool colour = static_cast<int>(i % channels) != spec.alpha_channel;
      pixels_[i] = Imath::half(encoded && colour ? srgbToLinear(decoded[i]) : decoded[i]);
    }
    spec.set_format(OIIO::TypeHalf);
    spec.channelformats.clear();
    spec.tile_width = spec.tile_height = spec.tile_depth = 0;  // served as scanlines
    spec.attribute("oiio:ColorSpace", "Linear");
    if (encoded) spec.attribute(kDecodedAttribute, 1);
    rowBytes_ = static_cast<size_t>(spec.width) * channels * sizeof(Imath::half);
    m_spec = spec;
    return true;
  }

  std::string name_;
  std::mutex mutex_;
  std::vector<Imath::half> pixels_;
  size_t rowBytes_ = 0;
};

OIIO::ImageInput* createLinearTextureInput() { return new LinearTextureInput; }

}  // namespace

bool registerTexture(const std::string& path, bool decodeColour) {
  if (decodeColour) {  // float images hold light already: read as stored
    auto in = OIIO::ImageInput::open(path);
    decodeColour = in && !in->spec().format.is_floating_point();
  }
  OIIO::ImageCache* cache = OIIO::ImageCache::create(true);  // the TextureSystem's
  // replace: a file an earlier render of this process registered is read again, and with
  // this render's reader.
  return cache->add_file(OIIO::ustring(path), decodeColour ? createLinearTextureInput : nullptr,
                         nullptr, true);
}

}  // namespace lvox
