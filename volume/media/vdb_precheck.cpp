#include "volume/media/vdb_precheck.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string_view>

#include "src/core/error.h"

namespace lvox {
namespace {

// File format versions of OpenVDB 10 (openvdb/version.h) that change the layout read here.
constexpr uint32_t kVersionSelectiveCompression = 220;
constexpr uint32_t kVersionFloatFrustumBbox = 221;  // the oldest OpenVDB 10 reads
constexpr uint32_t kVersionNodeMaskCompression = 222;
constexpr int64_t kMagic = 0x56444220;  // "VDB "

// Sizes that TypedMetadata<T>::readValue reads whatever the stored byte count says.
int fixedMetadataSize(std::string_view type) {
  struct Entry {
    std::string_view name;
    int size;
  };
  static constexpr Entry kSizes[] = {{"bool", 1},   {"int32", 4},  {"int64", 8},  {"float", 4},
                                     {"double", 8}, {"vec2i", 8},  {"vec2s", 8},  {"vec2d", 16},
                                     {"vec3i", 12}, {"vec3s", 12}, {"vec3d", 24}, {"vec4i", 16},
                                     {"vec4s", 16}, {"vec4d", 32}, {"mat4s", 64}, {"mat4d", 128}};
  for (const Entry& e : kSizes)
    if (type == e.name) return e.size;
  return -1;
}

class Walker {
 public:
  Walker(const std::string& path, const std::string& field)
      : in_(path, std::ios::binary), path_(path), field_(field) {
    in_.seekg(0, std::ios::end);
    size_ = static_cast<uint64_t>(std::max<std::streamoff>(0, in_.tellg()));
    in_.seekg(0);
  }

  void run() {
    if (read<int64_t>() != kMagic) fail("no VDB magic number");
    const uint32_t version = read<uint32_t>();
    // OpenVDB 10 still tries older layouts (and a corrupt version number); the layout
    // walked here is that of format 221 and later, so older files are refused.
    if (version < kVersionFloatFrustumBbox)
      fail("file format version " + std::to_string(version) + " is older than 221");
    skip(8);  // library version
    const bool hasOffsets = read<char>() != 0;
    if (version >= kVersionSelectiveCompression && version < kVersionNodeMaskCompression) skip(1);
    skip(36);  // UUID
    metaMap();
    if (!hasOffsets) fail("a streamed file without grid offsets");
    const int32_t grids = read<int32_t>();
    if (grids < 0 || static_cast<uint64_t>(grids) > remaining() / 36)
      fail("the file claims " + std::to_string(grids) + " grids");
    for (int32_t g = 0; g < grids; ++g) descriptorAndGrid(version);
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(path_, field_, "not a readable OpenVDB file: " + why);
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
  void skip(uint64_t n) {
    if (remaining() < n) fail("it ends inside its header (truncated?)");
    pos_ += n;
    in_.seekg(static_cast<std::streamoff>(pos_));
  }
  void seek(int64_t to, const char* what) {
    if (to < 0 || static_cast<uint64_t>(to) > size_)
      fail(std::string(what) + " offset " + std::to_string(to) + " lies outside the file");
    pos_ = static_cast<uint64_t>(to);
    in_.seekg(static_cast<std::streamoff>(pos_));
  }
  // OpenVDB's readString: a uint32 length, then the bytes.
  std::string string(const char* what) {
    const uint32_t n = read<uint32_t>();
    if (n > remaining())
      fail(std::string("a ") + what + " of " + std::to_string(n) + " bytes in " +
           std::to_string(remaining()) + " remaining");
    std::string s(n, '\0');
    if (n > 0) in_.read(s.data(), n);
    pos_ += n;
    return s;
  }

  // MetaMap::readMeta: a count, then name, type name and value of each entry.
  void metaMap() {
    const uint32_t count = read<uint32_t>();
    if (count > remaining() / 12) fail("it claims " + std::to_string(count) + " metadata entries");
    for (uint32_t i = 0; i < count; ++i) {
      string("metadata name");
      const std::string type = string("metadata type");
      const uint32_t bytes = read<uint32_t>();
      if (bytes > remaining()) fail("metadata '" + type.substr(0, 40) + "' runs past the end");
      const int fixed = fixedMetadataSize(type);
      if (type == "__delayedload")
        delayedLoad(bytes);
      else
        skip(fixed >= 0 ? static_cast<uint64_t>(fixed) : bytes);  // string, unknown: bytes
    }
  }

  // io::DelayedLoadMetadata::readValue: a mask (a compressed block, or one byte per
  // entry) and compressed sizes (a block, or one int64 per entry, or none).
  void delayedLoad(uint32_t bytes) {
    if (bytes == 0) return;
    const uint32_t count = read<uint32_t>();
    const uint32_t maskBytes = read<uint32_t>();
    skip(maskBytes > 0 ? maskBytes : count);
    const uint32_t sizeBytes = read<uint32_t>();
    if (sizeBytes == UINT32_MAX) return;
    skip(sizeBytes > 0 ? sizeBytes : static_cast<uint64_t>(count) * 8);
  }

  // GridDescriptor::read, then at the grid: compression flags, metadata, transform type.
  void descriptorAndGrid(uint32_t version) {
    string("grid name");
    string("grid type");
    string("instance parent name");
    const int64_t gridPos = read<int64_t>(), blockPos = read<int64_t>(), endPos = read<int64_t>();
    if (!(static_cast<uint64_t>(pos_) <= static_cast<uint64_t>(std::max<int64_t>(gridPos, 0)) &&
          gridPos <= blockPos && blockPos <= endPos))
      fail("grid offsets out of order");
    seek(endPos, "grid end");
    seek(gridPos, "grid");
    if (version >= kVersionNodeMaskCompression) skip(4);
    metaMap();
    string("transform type");
    seek(endPos, "grid end");
  }

  std::ifstream in_;
  const std::string& path_;
  const std::string& field_;
  uint64_t size_ = 0, pos_ = 0;
};

}  // namespace

void precheckVdbFile(const std::string& path, const std::string& field) {
  Walker(path, field).run();
}

}  // namespace lvox
