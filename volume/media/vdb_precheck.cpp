#include "volume/media/vdb_precheck.h"

#include <blosc.h>
#include <openvdb/openvdb.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string_view>
#include <vector>

#include "src/core/error.h"

namespace lvox {
namespace {

// File format versions of OpenVDB 10 (openvdb/version.h) that change the layout read here.
constexpr uint32_t kVersionNodeMaskCompression = 222;  // the oldest walked (OpenVDB 2.1)
constexpr int64_t kMagic = 0x56444220;                 // "VDB "

// Compression flags of a grid (openvdb/io/Compression.h).
constexpr uint32_t kZip = 0x1, kActiveMask = 0x2, kBlosc = 0x4;
// readCompressedValues' per-node flag: which inactive values and selection mask follow.
constexpr int8_t kOneInactiveValue = 2, kMaskNoInactiveValues = 3, kMaskOneInactiveValue = 4,
                 kMaskTwoInactiveValues = 5, kAllValues = 6;

// A FloatTree: Tree<RootNode<InternalNode<InternalNode<LeafNode<float,3>,4>,5>>>.
constexpr int kUpperLog2 = 5, kLowerLog2 = 4, kLeafLog2 = 3;
constexpr int32_t kRootChildDim = 1 << (kUpperLog2 + kLowerLog2 + kLeafLog2);  // 4096
constexpr std::string_view kFloatTree = "Tree_float_5_4_3";
constexpr std::string_view kHalfSuffix = "_HalfFloat";  // io::HALF_FLOAT_TYPENAME_SUFFIX
constexpr char kUniqueNameSeparator = '\x1e';           // GridDescriptor::stripSuffix

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

// The bytes each linear map's read() takes (openvdb/math/Maps.h; -1: not a linear map).
int linearMapSize(std::string_view type) {
  if (type == "AffineMap" || type == "UnitaryMap") return 128;         // a Mat4d
  if (type == "ScaleMap" || type == "UniformScaleMap") return 5 * 24;  // five Vec3d
  if (type == "ScaleTranslateMap" || type == "UniformScaleTranslateMap") return 6 * 24;
  if (type == "TranslationMap") return 24;
  return -1;
}

// What the header walk keeps of a grid for the tree walk.
struct GridEntry {
  std::string uniqueName, name, type, parent;
  bool halfSuffix = false, halfMeta = false;
  uint32_t compression = 0;
  int64_t treePos = 0, endPos = 0;  // the tree starts after the transform
  std::string transformType;
};

using Origin = std::array<int32_t, 3>;

// One root child: its origin and, in reading order, the active-value count of each leaf.
struct RootChild {
  Origin origin;
  std::vector<uint16_t> leafActive;
};

class Walker {
 public:
  Walker(const std::string& path, const std::string& field)
      : in_(path, std::ios::binary), path_(path), field_(field) {
    in_.seekg(0, std::ios::end);
    size_ = static_cast<uint64_t>(std::max<std::streamoff>(0, in_.tellg()));
    in_.seekg(0);
  }

  VdbTreeShape run(const std::string& gridName) {
    if (read<int64_t>() != kMagic) fail("no VDB magic number");
    version_ = read<uint32_t>();
    // OpenVDB 10 still tries older layouts (and a corrupt version number); the layout
    // walked here is that of format 222 (OpenVDB 2.1, 2013) and later.
    if (version_ < kVersionNodeMaskCompression)
      fail("file format version " + std::to_string(version_) + " is older than 222");
    skip(8);  // library version
    const bool hasOffsets = read<char>() != 0;
    skip(36);  // UUID
    metaMap(nullptr);
    if (!hasOffsets) fail("a streamed file without grid offsets");
    const int32_t grids = read<int32_t>();
    if (grids < 0 || static_cast<uint64_t>(grids) > remaining() / 36)
      fail("the file claims " + std::to_string(grids) + " grids");
    std::vector<GridEntry> entries;
    for (int32_t g = 0; g < grids; ++g) entries.push_back(descriptorAndGrid());
    return treeOf(entries, gridName);
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(path_, field_, "not a readable OpenVDB file: " + why);
  }
  uint64_t remaining() const { return size_ - pos_; }

  template <class T>
  T read() {
    T v{};
    if (remaining() < sizeof(T)) fail("it ends before what it declares (truncated?)");
    in_.read(reinterpret_cast<char*>(&v), sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  void readBytes(void* to, uint64_t n) {
    if (remaining() < n) fail("it ends before what it declares (truncated?)");
    in_.read(static_cast<char*>(to), static_cast<std::streamsize>(n));
    pos_ += n;
  }
  void skip(uint64_t n) {
    if (remaining() < n) fail("it ends before what it declares (truncated?)");
    pos_ += n;
    // Leaves' blocks are small and many: read on through the buffer rather than seek.
    if (n < (1u << 20))
      in_.ignore(static_cast<std::streamsize>(n));
    else
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
    readBytes(s.data(), n);
    return s;
  }

  // MetaMap::readMeta: a count, then name, type name and value of each entry. Sets
  // *halfFloat from the grid's `is_saved_as_half_float`, which sets how values are read.
  void metaMap(bool* halfFloat) {
    const uint32_t count = read<uint32_t>();
    if (count > remaining() / 12) fail("it claims " + std::to_string(count) + " metadata entries");
    for (uint32_t i = 0; i < count; ++i) {
      const std::string name = string("metadata name");
      const std::string type = string("metadata type");
      const uint32_t bytes = read<uint32_t>();
      if (bytes > remaining()) fail("metadata '" + type.substr(0, 40) + "' runs past the end");
      const int fixed = fixedMetadataSize(type);
      if (type == "__delayedload")
        delayedLoad(bytes);
      else if (halfFloat && name == "is_saved_as_half_float" && type == "bool")
        *halfFloat = read<char>() != 0;
      else
        skip(fixed >= 0 ? static_cast<uint64_t>(fixed) : bytes);  // string, unknown: bytes
    }
  }

  // io::DelayedLoadMetadata::readValue: a leaf count, a mask (a blosc block, or one byte
  // per leaf), compressed sizes (a blosc block, or one int64 per leaf, or none), then
  // whatever the declared size leaves (skipped, for newer versions). OpenVDB sizes both
  // arrays by the count before reading them.
  void delayedLoad(uint32_t bytes) {
    if (bytes == 0) return;
    const uint64_t start = pos_;
    const uint32_t leaves = read<uint32_t>();
    // A leaf takes at least its two 64-byte masks in a file.
    if (leaves > size_ / 128)
      fail("delayed-load metadata for " + std::to_string(leaves) + " leaves");
    const uint32_t maskBytes = read<uint32_t>();
    if (maskBytes > 0)
      bloscArray(maskBytes, leaves);
    else
      skip(leaves);
    const uint32_t sizeBytes = read<uint32_t>();
    if (sizeBytes > 0 && sizeBytes != UINT32_MAX)
      bloscArray(sizeBytes, uint64_t{leaves} * 8);
    else if (sizeBytes == 0)
      skip(uint64_t{leaves} * 8);
    if (pos_ - start < bytes) skip(bytes - (pos_ - start));
  }
  // Reads the header of a blosc block of `stored` bytes into `header` and checks it: blosc
  // trusts its header's sizes, so the compressed size must fit the block and the
  // uncompressed size must be `bytes`, or up to `padding` more.
  void bloscHeader(char (&header)[BLOSC_MIN_HEADER_LENGTH], uint64_t stored, uint64_t bytes,
                   uint64_t padding) {
    if (stored < BLOSC_MIN_HEADER_LENGTH) fail("a blosc block shorter than its header");
    readBytes(header, BLOSC_MIN_HEADER_LENGTH);
    size_t nbytes = 0, cbytes = 0, blocksize = 0;
    blosc_cbuffer_sizes(header, &nbytes, &cbytes, &blocksize);
    if (nbytes < bytes || nbytes > bytes + padding || cbytes > stored ||
        cbytes < BLOSC_MIN_HEADER_LENGTH)
      fail("a blosc block's header does not match its values");
  }
  // A blosc block of `stored` bytes that must hold `bytes`, which OpenVDB pads up to 128
  // bytes when they are few (points/StreamCompression.h), and reserves what the header says.
  void bloscArray(uint32_t stored, uint64_t bytes) {
    char header[BLOSC_MIN_HEADER_LENGTH];
    bloscHeader(header, stored, bytes, 128);
    skip(stored - BLOSC_MIN_HEADER_LENGTH);
  }

  // Transform::read: the map's type name, then its data (a frustum holds a second map).
  void mapData(const std::string& type, int depth) {
    if (const int size = linearMapSize(type); size >= 0) return skip(static_cast<uint64_t>(size));
    if (type != "NonlinearFrustumMap" || depth > 0)
      fail("unknown transform type '" + type.substr(0, 40) + "'");
    skip(48 + 8 + 8);  // bounding box, taper, depth
    mapData(string("frustum's second map type"), depth + 1);
  }

  // GridDescriptor::read, then at the grid: compression flags, metadata, transform.
  GridEntry descriptorAndGrid() {
    GridEntry e;
    e.uniqueName = string("grid name");
    e.name = e.uniqueName.substr(0, e.uniqueName.find(kUniqueNameSeparator));
    e.type = string("grid type");
    if (e.type.ends_with(kHalfSuffix)) {
      e.halfSuffix = true;
      e.type.resize(e.type.size() - kHalfSuffix.size());
    }
    e.parent = string("instance parent name");
    const int64_t gridPos = read<int64_t>(), blockPos = read<int64_t>();
    e.endPos = read<int64_t>();
    // An instance has no blocks of its own: OpenVDB writes its block offset as 0.
    const bool blocksInOrder = e.parent.empty() ? gridPos <= blockPos && blockPos <= e.endPos
                                                : blockPos == 0 && gridPos <= e.endPos;
    if (!(static_cast<uint64_t>(pos_) <= static_cast<uint64_t>(std::max<int64_t>(gridPos, 0)) &&
          blocksInOrder))
      fail("grid offsets out of order");
    seek(e.endPos, "grid end");
    seek(gridPos, "grid");
    e.compression = read<uint32_t>();
    metaMap(&e.halfMeta);
    e.transformType = string("transform type");
    mapData(e.transformType, 0);
    e.treePos = static_cast<int64_t>(pos_);
    if (e.treePos > e.endPos) fail("grid '" + e.name.substr(0, 40) + "' runs past its end");
    seek(e.endPos, "grid end");
    return e;
  }

  VdbTreeShape treeOf(const std::vector<GridEntry>& entries, const std::string& gridName) {
    const GridEntry* grid = nullptr;
    int matches = 0;
    for (const GridEntry& e : entries)
      if (e.name == gridName) grid = &e, ++matches;
    if (matches != 1 || grid->type != kFloatTree) return {};  // the loader names the problem
    const GridEntry* owner = grid;                            // the grid whose tree is read
    if (!grid->parent.empty()) {
      owner = nullptr;
      for (const GridEntry& e : entries)
        if (e.uniqueName == grid->parent) owner = &e;
      if (!owner || !owner->parent.empty() || owner->type != kFloatTree)
        fail("grid '" + gridName + "' is an instance of a grid the file does not hold");
    }
    if (owner->halfSuffix != owner->halfMeta)
      fail("grid '" + owner->name.substr(0, 40) + "' disagrees with itself on half floats");
    seek(owner->treePos, "tree");
    end_ = static_cast<uint64_t>(owner->endPos);
    compression_ = owner->compression;
    half_ = owner->halfMeta;
    return tree();
  }

  // Tree::readTopology (a buffer count, then the root), then Tree::readBuffers.
  VdbTreeShape tree() {
    VdbTreeShape shape;
    if (read<int32_t>() != 1) fail("a tree of other than one buffer");  // OpenVDB reads on
    read<float>();                                                      // background
    const uint32_t tiles = read<uint32_t>(), children = read<uint32_t>();
    if (tiles > remainingInGrid() / 17) fail("the root claims " + std::to_string(tiles) + " tiles");
    for (uint32_t t = 0; t < tiles; ++t) {
      rootOrigin("tile");
      read<float>();
      if (read<uint8_t>() > 1) fail("a root tile's active flag is not a bool");
    }
    shape.rootTiles = tiles;
    // An upper node takes at least its origin, two masks and a compression flag.
    constexpr uint64_t kMinUpperBytes = 12 + 2 * (1u << (3 * kUpperLog2)) / 8 + 1;
    if (children > remainingInGrid() / kMinUpperBytes)
      fail("the root claims " + std::to_string(children) + " children");
    std::vector<RootChild> rootChildren(children);
    for (RootChild& child : rootChildren) {
      child.origin = rootOrigin("child");
      internalNode(kUpperLog2, child.leafActive, shape);
    }
    // RootNode::readBuffers visits its children in the order of its map: by origin.
    std::sort(rootChildren.begin(), rootChildren.end(),
              [](const RootChild& a, const RootChild& b) { return a.origin < b.origin; });
    for (size_t i = 1; i < rootChildren.size(); ++i)
      if (rootChildren[i].origin == rootChildren[i - 1].origin)
        fail("two root children at one origin");
    for (const RootChild& child : rootChildren)
      for (const uint16_t active : child.leafActive) leafBuffer(active);
    if (pos_ > end_) fail("the tree runs past its grid's end");
    return shape;
  }
  uint64_t remainingInGrid() const { return end_ > pos_ ? end_ - pos_ : 0; }

  Origin rootOrigin(const char* what) {
    Origin o;
    for (int32_t& c : o) c = read<int32_t>();
    for (const int32_t c : o)
      if (c % kRootChildDim != 0) fail(std::string("a root ") + what + " off the 4096 grid");
    return o;
  }

  // A node mask of 2^(3 log2) bits; returns how many are on, and the bits in `bits`.
  uint32_t mask(int log2, std::vector<uint64_t>& bits) {
    bits.resize((size_t{1} << (3 * log2)) / 64);
    readBytes(bits.data(), bits.size() * 8);
    uint32_t on = 0;
    for (const uint64_t w : bits) on += static_cast<uint32_t>(std::popcount(w));
    return on;
  }

  // InternalNode::readTopology: child mask, value mask, the values, then each child.
  void internalNode(int log2, std::vector<uint16_t>& leafActive, VdbTreeShape& shape) {
    ++(log2 == kUpperLog2 ? shape.upperNodes : shape.lowerNodes);
    std::vector<uint64_t> childMask, valueMask;
    mask(log2, childMask);
    const uint32_t active = mask(log2, valueMask);
    compressedValues(uint32_t{1} << (3 * log2), active, /*decompress=*/true);
    for (size_t w = 0; w < childMask.size(); ++w)
      for (uint64_t bits = childMask[w]; bits != 0; bits &= bits - 1) {
        if (log2 == kUpperLog2) {
          internalNode(kLowerLog2, leafActive, shape);
        } else {
          leafActive.push_back(static_cast<uint16_t>(mask(kLeafLog2, leafMask_)));
          ++shape.leaves;
        }
      }
  }

  // LeafNode::readBuffers: the value mask again, then the values.
  void leafBuffer(uint16_t topologyActive) {
    if (mask(kLeafLog2, leafMask_) != topologyActive)
      fail("a leaf's value mask differs between its topology and its values");
    compressedValues(1u << (3 * kLeafLog2), topologyActive, /*decompress=*/false);
  }

  // io::readCompressedValues for floats: a flag, inactive values, a selection mask, then the
  // active values (mask compression) or all of them, as floats or halves.
  void compressedValues(uint32_t count, uint32_t active, bool decompress) {
    const int8_t flag = read<int8_t>();
    if (flag < 0 || flag > kAllValues) fail("a node's value flag is " + std::to_string(flag));
    if (flag == kOneInactiveValue || flag == kMaskOneInactiveValue ||
        flag == kMaskTwoInactiveValues)
      skip(sizeof(float));
    if (flag == kMaskTwoInactiveValues) skip(sizeof(float));
    if (flag == kMaskNoInactiveValues || flag == kMaskOneInactiveValue ||
        flag == kMaskTwoInactiveValues)
      skip(count / 8);
    const uint32_t stored = (compression_ & kActiveMask) && flag != kAllValues ? active : count;
    if (half_ && stored == 0) return;  // HalfReader reads nothing for no values
    block(uint64_t{stored} * (half_ ? 2 : sizeof(float)), decompress);
  }

  // io::readData: raw bytes, or a zip or blosc block led by its int64 size (negative:
  // stored raw). `decompress` checks that the block gives exactly `bytes`.
  void block(uint64_t bytes, bool decompress) {
    if (!(compression_ & (kZip | kBlosc))) return skip(bytes);
    const int64_t size = read<int64_t>();
    if (size <= 0) {
      if (static_cast<uint64_t>(0) - static_cast<uint64_t>(size) != bytes)
        fail("a raw block of " + std::to_string(size) + " bytes where " + std::to_string(bytes) +
             " are read");
      return skip(bytes);
    }
    if (static_cast<uint64_t>(size) > remainingInGrid())
      fail("a compressed block of " + std::to_string(size) + " bytes runs past the grid");
    const bool blosc = compression_ & kBlosc;
    if (!decompress && !blosc) return skip(static_cast<uint64_t>(size));
    std::vector<char> packed;
    if (blosc) {
      char header[BLOSC_MIN_HEADER_LENGTH];
      bloscHeader(header, static_cast<uint64_t>(size), bytes, 0);
      if (!decompress) return skip(static_cast<uint64_t>(size) - BLOSC_MIN_HEADER_LENGTH);
      packed.assign(header, header + BLOSC_MIN_HEADER_LENGTH);
      packed.resize(static_cast<size_t>(size));
      readBytes(packed.data() + BLOSC_MIN_HEADER_LENGTH,
                static_cast<uint64_t>(size) - BLOSC_MIN_HEADER_LENGTH);
    } else {
      packed.resize(static_cast<size_t>(size));
      readBytes(packed.data(), static_cast<uint64_t>(size));
    }
    std::vector<char> values(std::max<uint64_t>(bytes, 1));
    bool exact = false;
    if (blosc) {
      exact =
          blosc_decompress_ctx(packed.data(), values.data(), bytes, 1) == static_cast<int>(bytes);
    } else {
      uLongf length = static_cast<uLongf>(bytes);
      exact = uncompress(reinterpret_cast<Bytef*>(values.data()), &length,
                         reinterpret_cast<const Bytef*>(packed.data()),
                         static_cast<uLong>(size)) == Z_OK &&
              length == bytes;
    }
    if (!exact) fail("a node's compressed values do not decompress to their size");
  }

  std::ifstream in_;
  const std::string& path_;
  const std::string& field_;
  uint64_t size_ = 0, pos_ = 0, end_ = 0;
  uint32_t version_ = 0, compression_ = 0;
  bool half_ = false;
  std::vector<uint64_t> leafMask_;  // reused: leaves are many
};

}  // namespace

uint64_t VdbTreeShape::bytes() const {
  using Leaf = openvdb::FloatTree::LeafNodeType;
  using Upper = openvdb::FloatTree::RootNodeType::ChildNodeType;
  using Lower = Upper::ChildNodeType;
  constexpr uint64_t kRootEntry = 64;  // a std::map node of the root's table
  return (rootTiles + upperNodes) * kRootEntry + upperNodes * sizeof(Upper) +
         lowerNodes * sizeof(Lower) + leaves * (sizeof(Leaf) + Leaf::SIZE * sizeof(float));
}

VdbTreeShape precheckVdbFile(const std::string& path, const std::string& field,
                             const std::string& gridName) {
  return Walker(path, field).run(gridName);
}

}  // namespace lvox
