// The walk of volume/media/vdb_precheck.h: real files pass it and its node counts are
// OpenVDB's; files whose lengths made OpenVDB allocate gigabytes, whose trees made it loop
// or leak (found by fuzzing) are refused, fast; whatever passes, OpenVDB reads without an
// exception inside the topology (where it leaks).
#include <gtest/gtest.h>
#include <malloc.h>
#include <openvdb/openvdb.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>

#include "src/core/error.h"
#include "test_util.h"
#include "volume/media/vdb_loader.h"
#include "volume/media/vdb_precheck.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string error(const fs::path& p) {
  try {
    precheckVdbFile(p.string(), "media[0].file", "density");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(VdbPrecheck, RealFilesPass) {
  EXPECT_EQ(error(fs::path(LVOX_SOURCE_DIR) / "assets/smoke_plume.vdb"), "");
  EXPECT_EQ(error(fs::path(LVOX_SOURCE_DIR) / "tests/fuzz/seeds/vdb/density_small.vdb"), "");
  const fs::path shared = fs::path(LVOX_SHARED_DIR) / "assets/vdb";
  if (!fs::exists(shared)) GTEST_SKIP() << "shared assets absent";
  for (const char* name : {"smoke.vdb", "blender_smoke_plume.vdb", "wdas_cloud_sixteenth.vdb"})
    EXPECT_EQ(error(shared / name), "") << name;
}

// The seed with the length of its grid's name (the first string after the file's metadata
// and the grid count) set to 4 GiB - 1.
TEST(VdbPrecheck, HugeStringLengthIsRefused) {
  std::string bytes = readAll(fs::path(LVOX_SOURCE_DIR) / "tests/fuzz/seeds/vdb/density_small.vdb");
  const size_t name = bytes.find("density");
  ASSERT_NE(name, std::string::npos);
  const uint32_t huge = 0xFFFFFFFFu;
  std::memcpy(&bytes[name - 4], &huge, 4);
  const auto dir = test::tempDir();
  test::writeFile(dir / "huge.vdb", bytes);
  const std::string msg = error(dir / "huge.vdb");
  EXPECT_NE(msg.find("of 4294967295 bytes in"), std::string::npos) << msg;
}

// OpenVDB 10 goes on reading a file whose format version is corrupt (0 here): refused.
TEST(VdbPrecheck, OldOrCorruptVersionIsRefused) {
  std::string bytes = readAll(fs::path(LVOX_SOURCE_DIR) / "tests/fuzz/seeds/vdb/density_small.vdb");
  const uint32_t zero = 0;
  std::memcpy(&bytes[8], &zero, 4);
  const auto dir = test::tempDir();
  test::writeFile(dir / "old.vdb", bytes);
  EXPECT_NE(error(dir / "old.vdb").find("version 0 is older than 222"), std::string::npos);
}

// A small grid in two root children (a few dozen leaves, an inactive value, a lower-level
// tile), written by OpenVDB with `compression` and, when `half`, values as half floats.
fs::path writeTestGrid(const fs::path& path, uint32_t compression, bool half,
                       bool rootTile = false) {
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("density");
  grid->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
  grid->setSaveFloatAsHalf(half);
  auto acc = grid->getAccessor();
  for (int i = 0; i < 40; ++i)
    acc.setValue(openvdb::Coord(3 * i, i % 7, 2 * i % 11), 0.25f + 0.01f * static_cast<float>(i));
  acc.setValue(openvdb::Coord(5000, -3, 17), 2.0f);  // the second root child
  acc.setValueOff(openvdb::Coord(3, 3, 3), 0.5f);
  grid->tree().addTile(1, openvdb::Coord(64, 64, 64), 0.75f, true);
  if (rootTile) grid->tree().addTile(3, openvdb::Coord(-8192, 0, 0), 0.1f, true);
  openvdb::io::File file(path.string());
  file.setCompression(compression);
  file.write({grid});
  return path;
}

struct Codec {
  const char* name;
  uint32_t flags;
};
constexpr Codec kCodecs[] = {
    {"none", openvdb::io::COMPRESS_NONE},
    {"active mask", openvdb::io::COMPRESS_ACTIVE_MASK},
    {"zip", openvdb::io::COMPRESS_ZIP},
    {"zip, active mask", openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK},
    {"blosc", openvdb::io::COMPRESS_BLOSC},
    {"blosc, active mask", openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK}};

// The walk counts the nodes OpenVDB reads, for every codec, with floats and halves, and a
// root tile; its byte count is within 10 % of OpenVDB's memUsage of the tree it reads.
TEST(VdbPrecheck, TreeShapesAreOpenVdbs) {
  const auto dir = test::tempDir();
  for (const Codec& codec : kCodecs)
    for (const bool half : {false, true})
      for (const bool rootTile : {false, true}) {
        SCOPED_TRACE(std::string(codec.name) + (half ? ", half" : "") +
                     (rootTile ? ", root tile" : ""));
        const fs::path path = writeTestGrid(dir / "grid.vdb", codec.flags, half, rootTile);
        const VdbTreeShape shape = precheckVdbFile(path.string(), "media[0].file", "density");
        openvdb::io::File file(path.string());
        file.open(false);
        const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("density"));
        const auto& tree = grid->tree();
        const std::vector<openvdb::Index32> nodes = tree.nodeCount();  // leaves first
        EXPECT_EQ(shape.leaves, nodes[0]);
        EXPECT_EQ(shape.lowerNodes, nodes[1]);
        EXPECT_EQ(shape.upperNodes, nodes[2]);
        EXPECT_EQ(shape.rootTiles, rootTile ? 1u : 0u);
        const double ratio =
            static_cast<double>(shape.bytes()) / static_cast<double>(tree.memUsage());
        EXPECT_NEAR(ratio, 1.0, 0.1);
      }
}

// A grid that shares its tree with another is written as an instance of it: the walk
// follows the instance to its parent's tree, which is what OpenVDB reads for it.
TEST(VdbPrecheck, AnInstanceIsWalkedThroughItsParentsTree) {
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("smoke");
  grid->tree().setValue(openvdb::Coord(1, 2, 3), 1.0f);
  grid->tree().setValue(openvdb::Coord(100, 2, 3), 2.0f);
  openvdb::GridBase::Ptr instance = grid->copyGrid();  // shares the tree
  instance->setName("density");
  const fs::path path = test::tempDir() / "instance.vdb";
  openvdb::io::File(path.string()).write({grid, instance});
  const VdbTreeShape shape = precheckVdbFile(path.string(), "media[0].file", "density");
  EXPECT_EQ(shape.leaves, 2u);
  EXPECT_EQ(shape.lowerNodes, 1u);
  GridLoadReport report;
  EXPECT_EQ(
      loadVdbGrid(path.string(), "density", Transform(), "media[0].file", report).activeVoxels(),
      2u);
}

TEST(VdbPrecheck, RealTreesAreCountedAsOpenVdbReadsThem) {
  const fs::path shared = fs::path(LVOX_SHARED_DIR) / "assets/vdb";
  if (!fs::exists(shared)) GTEST_SKIP() << "shared assets absent";
  const fs::path path = shared / "wdas_cloud_sixteenth.vdb";
  const VdbTreeShape shape = precheckVdbFile(path.string(), "media[0].file", "density");
  openvdb::initialize();
  openvdb::io::File file(path.string());
  file.open(false);
  const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("density"));
  EXPECT_EQ(shape.leaves, grid->tree().leafCount());
  EXPECT_NEAR(static_cast<double>(shape.bytes()) / static_cast<double>(grid->tree().memUsage()),
              1.0, 0.1);
}

// Cuts of a file, through its header and its tree, are refused by the walk: OpenVDB would
// read on past the end (or leak what it had read of the topology). Every cut of the fuzz
// seed; of the written grids (22 kB, mostly the upper nodes' masks) every cut in the first
// and last kilobyte and every 16th between.
TEST(VdbPrecheck, EveryTruncationIsRefused) {
  const auto dir = test::tempDir();
  std::vector<std::string> files = {
      readAll(fs::path(LVOX_SOURCE_DIR) / "tests/fuzz/seeds/vdb/density_small.vdb")};
  for (const uint32_t codec : {kCodecs[3].flags, kCodecs[5].flags})
    files.push_back(readAll(writeTestGrid(dir / "grid.vdb", codec, false)));
  for (const std::string& bytes : files) {
    size_t passed = 0;
    for (size_t cut = 0; cut < bytes.size();
         cut += cut < 1024 || cut + 1024 >= bytes.size() ? 1 : 16) {
      test::writeFile(dir / "cut.vdb", bytes.substr(0, cut));
      passed += error(dir / "cut.vdb") == "";
    }
    EXPECT_EQ(passed, 0u) << bytes.size() << " bytes";
    test::writeFile(dir / "whole.vdb", bytes);
    EXPECT_EQ(error(dir / "whole.vdb"), "");
  }
}

// Replaces the first `from` in `bytes` (after `after`) by `to`.
void replaceOnce(std::string& bytes, const std::string& from, const std::string& to,
                 size_t after = 0) {
  const size_t at = bytes.find(from, after);
  ASSERT_NE(at, std::string::npos);
  bytes.replace(at, from.size(), to);
}

std::string int32s(std::initializer_list<int32_t> values) {
  std::string out;
  for (const int32_t v : values) out.append(reinterpret_cast<const char*>(&v), 4);
  return out;
}

// Stop 27's fuzz finding: OpenVDB skips what a delayed-load metadata value declares beyond
// what it reads; the walk did not, so it read the next metadata name elsewhere than
// OpenVDB, which then allocated 1.8 GB for it. The walk now reads the name OpenVDB reads.
TEST(VdbPrecheck, DelayedLoadMetadataIsSkippedAsOpenVdbSkipsIt) {
  const std::string msg = error(fs::path(LVOX_SOURCE_DIR) /
                                "tests/fuzz/corpus/vdb/fuzz27-oom-delayed-load-tail-421cd5b5.vdb");
  EXPECT_NE(msg.find("a metadata name of 1818846720 bytes"), std::string::npos) << msg;
}

// The root's counts and origins, edited in a real file: OpenVDB loops over a tile count
// it cannot read and leaks the first of two children at one origin.
TEST(VdbPrecheck, RootCountsAndOriginsAreChecked) {
  const auto dir = test::tempDir();
  const std::string good = readAll(writeTestGrid(dir / "grid.vdb", kCodecs[5].flags, false));
  // The root: no tiles, two children, the first at the origin; the second at (4096, -4096, 0).
  const std::string root = int32s({0, 2, 0, 0, 0});
  const std::string second = int32s({4096, -4096, 0});
  const auto check = [&](const std::string& bytes, const std::string& expected) {
    test::writeFile(dir / "edited.vdb", bytes);
    const std::string msg = error(dir / "edited.vdb");
    EXPECT_NE(msg.find(expected), std::string::npos) << msg;
  };
  std::string bytes = good;
  replaceOnce(bytes, root, int32s({0x7fffffff, 2, 0, 0, 0}));
  check(bytes, "the root claims 2147483647 tiles");
  bytes = good;
  replaceOnce(bytes, root, int32s({0, 100000, 0, 0, 0}));
  check(bytes, "the root claims 100000 children");
  const size_t rootAt = good.find(root);
  bytes = good;
  replaceOnce(bytes, second, int32s({0, 0, 0}), rootAt + root.size());
  check(bytes, "two root children at one origin");
  bytes = good;
  replaceOnce(bytes, second, int32s({4095, -4096, 0}), rootAt + root.size());
  check(bytes, "a root child off the 4096 grid");
}

// The bytes a process has allocated (glibc's count; under AddressSanitizer its
// LeakSanitizer checks the same at exit).
size_t allocatedBytes() {
  const struct mallinfo2 info = mallinfo2();
  return info.uordblks + info.hblkhd;
}

// Each byte of a tree's topology and values corrupted in turn: the load either succeeds or
// throws an InputError, and never leaks (OpenVDB leaked a root child, 270 kB and up, when
// its topology read threw). Blosc and zip, with the active mask.
TEST(VdbPrecheck, CorruptTreesAreRefusedWithoutLeaking) {
  const auto dir = test::tempDir();
  for (const uint32_t codec : {kCodecs[3].flags, kCodecs[5].flags}) {
    const std::string good = readAll(writeTestGrid(dir / "grid.vdb", codec, false));
    const size_t tree = good.find(int32s({0, 2, 0, 0, 0}));  // root counts, first origin
    ASSERT_NE(tree, std::string::npos);
    const auto load = [&](const std::string& bytes) {
      test::writeFile(dir / "corrupt.vdb", bytes);
      GridLoadReport report;
      try {
        (void)loadVdbGrid((dir / "corrupt.vdb").string(), "density", Transform(), "media[0].file",
                          report);
        return std::string();
      } catch (const InputError& e) {
        return std::string(e.what());
      }
    };
    load(good);  // OpenVDB's registries and caches, once
    int refusedByWalk = 0, refusedAfter = 0, read = 0;
    size_t leaked = 0;
    size_t corrupted = 0;
    for (size_t at = tree - 8; at < good.size(); ++at) {
      // Every byte that is not zero, and every 16th zero (the masks are mostly zeros).
      if (good[at] == 0 && at % 16 != 0) continue;
      ++corrupted;
      std::string bytes = good;
      bytes[at] = static_cast<char>(bytes[at] ^ 0x5a);
      const size_t before = allocatedBytes();
      const std::string msg = load(bytes);
      leaked = std::max(leaked, allocatedBytes() - std::min(allocatedBytes(), before));
      if (msg.empty())
        ++read;
      else if (msg.find("not a readable OpenVDB file") != std::string::npos &&
               error(dir / "corrupt.vdb") != "")
        ++refusedByWalk;
      else
        ++refusedAfter;
    }
    std::cout << "[ codec " << codec << " ] " << corrupted
              << " corrupted bytes: refused by the walk " << refusedByWalk << ", after it "
              << refusedAfter << ", read " << read << "; most retained " << leaked << " bytes\n";
    EXPECT_GT(refusedByWalk, 0);
    EXPECT_LT(leaked, 64u << 10);
  }
}

}  // namespace
}  // namespace lvox
