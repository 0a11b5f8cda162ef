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
      if (attribute == "dataWindow" && type == "box2i" && size == 16) {
        int32_t box[4];
        for (int32_t& b : box) b = read<int32_t>();
        checkRows(static_cast<int64_t>(box[3]) - box[1] + 1);
      } else {
        pos_ += static_cast<uint64_t>(size);
        in_.seekg(static_cast<std::streamoff>(pos_));
      }
    }
    return any;
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
