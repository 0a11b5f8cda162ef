#include "src/core/exr_channels.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>

#include "src/core/atomic_file.h"
#include "src/core/error.h"
#include "src/core/exr_input.h"

namespace lvox {
namespace {

// Rank of a channel's suffix inside its layer: the colour channels first, in RGB order.
int suffixRank(const std::string& name) {
  static const std::array<std::string, 6> order{"R", "G", "B", "A", "Y", "Z"};
  const size_t dot = name.rfind('.');
  const std::string suffix = dot == std::string::npos ? name : name.substr(dot + 1);
  const auto it = std::find(order.begin(), order.end(), suffix);
  return static_cast<int>(it - order.begin());
}

// A Slice whose base is offset so that pixel (dw.min.x, dw.min.y) lands at index 0.
Imf::Slice floatSlice(std::vector<float>& plane, const Imath::Box2i& dw, int width) {
  const size_t xStride = sizeof(float), yStride = sizeof(float) * static_cast<size_t>(width);
  char* base = reinterpret_cast<char*>(plane.data()) -
               static_cast<ptrdiff_t>(dw.min.x) * static_cast<ptrdiff_t>(xStride) -
               static_cast<ptrdiff_t>(dw.min.y) * static_cast<ptrdiff_t>(yStride);
  return Imf::Slice(Imf::FLOAT, base, xStride, yStride);
}

ExrChannels readOpened(const std::string& path, Imf::InputFile& in) {
  const ExrSize size = checkedExrSize(path, in);
  const Imath::Box2i& dw = size.window;
  ExrChannels out;
  out.width = size.width;
  out.height = size.height;
  const Imf::ChannelList& list = in.header().channels();
  for (auto it = list.begin(); it != list.end(); ++it) {
    if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
      throw InputError(path, it.name(), "subsampled channels are not supported");
    out.names.push_back(it.name());
  }
  if (out.names.empty()) throw InputError(path, "", "the EXR has no channels");
  sortChannelNames(out.names);
  out.planes.resize(out.names.size());
  Imf::FrameBuffer fb;
  for (size_t c = 0; c < out.names.size(); ++c) {
    out.planes[c].assign(static_cast<size_t>(size.width) * static_cast<size_t>(size.height), 0.0f);
    fb.insert(out.names[c], floatSlice(out.planes[c], dw, out.width));
  }
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  for (auto it = in.header().begin(); it != in.header().end(); ++it)
    if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
      out.metadata[it.name()] = s->value();
  return out;
}

}  // namespace

const std::vector<float>* ExrChannels::find(const std::string& name) const {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? nullptr : &planes[static_cast<size_t>(it - names.begin())];
}

std::string channelLayer(const std::string& name) {
  const size_t dot = name.rfind('.');
  return dot == std::string::npos ? std::string() : name.substr(0, dot);
}

void sortChannelNames(std::vector<std::string>& names) {
  std::sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
    const std::string la = channelLayer(a), lb = channelLayer(b);
    if (la != lb) return la < lb;
    const int ra = suffixRank(a), rb = suffixRank(b);
    return ra != rb ? ra < rb : a < b;
  });
}

ExrChannels readExrChannels(const std::string& path) {
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw InputError(path, "", std::string("cannot open: ") + std::strerror(errno));
  }
  try {
    Imf::InputFile in(path.c_str());
    return readOpened(path, in);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    std::string what = e.what();
    if (what.size() > 200) what = what.substr(0, 200) + "...";
    throw InputError(path, "", "not a readable OpenEXR file: " + what);
  }
}

void writeExrChannels(const std::string& path, const ExrChannels& channels) {
  const size_t n = static_cast<size_t>(channels.width) * static_cast<size_t>(channels.height);
  if (channels.width <= 0 || channels.height <= 0 || channels.names.empty() ||
      channels.names.size() != channels.planes.size())
    throw InputError(path, "", "image has an invalid size");
  for (const std::vector<float>& p : channels.planes)
    if (p.size() != n) throw InputError(path, "", "a channel has the wrong number of pixels");
  // No NaN or infinity into a file (as writeExr); negative values stay, since an AOV such
  // as a normal or a signed difference may be negative.
  std::vector<std::vector<float>> planes = channels.planes;
  for (std::vector<float>& p : planes)
    for (float& v : p)
      if (!std::isfinite(v)) v = 0.0f;
  publishAtomically(path, [&](const std::string& tmp) {
    Imf::Header header(channels.width, channels.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const auto& [key, value] : channels.metadata)
      header.insert(key, Imf::StringAttribute(value));
    Imf::FrameBuffer fb;
    const size_t row = sizeof(float) * static_cast<size_t>(channels.width);
    for (size_t c = 0; c < channels.names.size(); ++c) {
      header.channels().insert(channels.names[c], Imf::Channel(Imf::FLOAT));
      char* base = reinterpret_cast<char*>(planes[c].data());
      fb.insert(channels.names[c], Imf::Slice(Imf::FLOAT, base, sizeof(float), row));
    }
    Imf::OutputFile out(tmp.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(channels.height);
  });
}

std::optional<Image> colourImage(const ExrChannels& channels) {
  const std::vector<float>* r = channels.find("R");
  const std::vector<float>* g = channels.find("G");
  const std::vector<float>* b = channels.find("B");
  if (!r || !g || !b) r = g = b = channels.find("Y");
  if (!r) return std::nullopt;
  Image image(channels.width, channels.height);
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = RGB((*r)[i], (*g)[i], (*b)[i]);
  return image;
}

}  // namespace lvox
