#include "src/core/exr_precheck.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>

#include "src/core/error.h"

namespace lvox {
namespace {

constexpr int32_t kMagic = 20000630;
constexpr uint32_t kTiledFlag = 0x200, kLongNamesFlag = 0x400, kMultiPartFlag = 0x1000;
// The most scanlines one chunk holds (DWAB); each chunk has an 8-byte offset.
constexpr uint64_t kMaxLinesPerChunk = 256;

// The bytes OpenEXR 3.1 reads for an attribute of a fixed-size type: it reads the value's
// own fields and not the size the file declares, so a header whose sizes lie is walked
// as OpenEXR walks it (found by fuzzing: a channel list declared 54 bytes long, read to
// its terminator by OpenEXR, put the next attributes elsewhere than the sizes said).
// 0: not a fixed-size type (strings, vectors, opaque types read the declared size).
uint64_t fixedValueBytes(const std::string& type) {
  static const std::pair<const char*, uint64_t> kFixed[] = {
      {"box2i", 16},      {"box2f", 16},   {"chromaticities", 32},
      {"compression", 1}, {"double", 8},   {"envmap", 1},
      {"float", 4},       {"int", 4},      {"keycode", 28},
      {"lineOrder", 1},   {"m33f", 36},    {"m33d", 72},
      {"m44f", 64},       {"m44d", 128},   {"rational", 8},
      {"tiledesc", 9},    {"timecode", 8}, {"deepImageState", 1},
      {"v2i", 8},         {"v2f", 8},      {"v2d", 16},
      {"v3i", 12},        {"v3f", 12},     {"v3d", 24}};
  for (const auto& [name, bytes] : kFixed)
    if (type == name) return bytes;
  return 0;
}

class Walker {
 public:
  explicit Walker(const std::string& path) : in_(path, std::ios::binary), path_(path) {
    in_.seekg(0, std::ios::end);
    size_ = static_cast<uint64_t>(std::max<std::streamoff>(0, in_.tellg()));
    in_.seekg(0);
  }

  void run() {
    if (read<int32_t>() != kMagic) return;  // not EXR: OpenEXR says so itself
    const uint32_t version = read<uint32_t>();
    const bool multiPart = (version & kMultiPartFlag) != 0;
    tiled_ = (version & kTiledFlag) != 0;
    maxName_ = (version & kLongNamesFlag) ? 255 : 31;
    do {
      if (!header() && multiPart) break;  // an empty header ends the list of parts
    } while (multiPart);
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(path_, "", "not a readable OpenEXR file: " + why);
  }
  uint64_t remaining() const { return size_ - pos_; }

  template <class T>
  T read() {
    T v{};
    if (remaining() < sizeof(T)) fail("it ends inside its header (truncated?)");
    in_.read(reinterpret_cast<char*>(&v), sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::string name() {
    std::string s;
    for (char c; (c = read<char>()) != '\0';) {
      if (s.size() >= maxName_) fail("an attribute name longer than " + std::to_string(maxName_));
      s += c;
    }
    return s;
  }

  // One header: attributes until an empty name. Returns false for an empty header.
  bool header() {
    bool any = false;
    for (std::string attribute = name(); !attribute.empty(); attribute = name()) {
      any = true;
      const std::string type = name();
      const int32_t size = read<int32_t>();
      if (size < 0 || static_cast<uint64_t>(size) > remaining())
        fail("attribute '" + attribute + "' claims " + std::to_string(size) + " bytes, " +
             std::to_string(remaining()) + " remain");
      if (attribute == "dataWindow" && type == "box2i") {
        int32_t box[4];
        for (int32_t& b : box) b = read<int32_t>();
        checkRows(static_cast<int64_t>(box[3]) - box[1] + 1);
      } else if (type == "chlist") {
        channelList();
      } else if (type == "preview") {
        const uint64_t width = read<uint32_t>(), height = read<uint32_t>();
        if (width * height * 4 > remaining())  // OpenEXR allocates the pixels first
          fail("a preview image of " + std::to_string(width) + " x " + std::to_string(height) +
               " pixels in " + std::to_string(remaining()) + " bytes");
        skip(width * height * 4);
      } else {
        const uint64_t fixed = fixedValueBytes(type);
        skip(fixed > 0 ? fixed : static_cast<uint64_t>(size));
      }
    }
    return any;
  }

  void skip(uint64_t bytes) {
    if (bytes > remaining()) fail("it ends inside its header (truncated?)");
    pos_ += bytes;
    in_.seekg(static_cast<std::streamoff>(pos_));
  }

  // A channel list as OpenEXR reads it: channels until an empty name, each a name and 16
  // bytes (pixel type, pLinear, 3 reserved, x and y sampling), whatever its declared size.
  void channelList() {
    while (!name().empty()) skip(16);
  }

  // OpenEXR allocates one 8-byte offset per chunk of a scanline image before reading it.
  void checkRows(int64_t rows) const {
    if (tiled_ || rows <= 0) return;  // OpenEXR or readExr refuse empty windows
    if (static_cast<uint64_t>(rows) / kMaxLinesPerChunk * 8 > size_)
      fail("a data window of " + std::to_string(rows) + " rows in a file of " +
           std::to_string(size_) + " bytes");
  }

  std::ifstream in_;
  const std::string& path_;
  uint64_t size_ = 0, pos_ = 0;
  bool tiled_ = false;
  size_t maxName_ = 31;
};

}  // namespace

void precheckExrFile(const std::string& path) { Walker(path).run(); }

}  // namespace lvox
