// Writes the generated seed inputs of the fuzz harnesses (run by hand, output committed
// under tests/fuzz/seeds/; the scene seeds are copies of scenes/*.json and hand-written):
//   build-fuzz/tests/fuzz/lvox_make_fuzz_seeds tests/fuzz/seeds
// Each file is tiny (< 2 KB) so that libFuzzer mutates structure, not payload.
#include <openvdb/openvdb.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "src/core/image_io.h"

namespace fs = std::filesystem;

namespace {

void write(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
}

const char* kPlyHeader =
    "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 2\nproperty list uchar int vertex_indices\nend_header\n";

// The quad of the ascii seed in binary: four float vertices, two triangles.
std::string binaryPlyBody(bool bigEndian) {
  std::string body;
  auto put = [&](const void* p, size_t n) {
    std::string bytes(static_cast<const char*>(p), n);
    if (bigEndian) std::reverse(bytes.begin(), bytes.end());
    body += bytes;
  };
  const float v[4][3] = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}};
  for (const auto& p : v)
    for (float c : p) put(&c, 4);
  const int faces[2][3] = {{0, 1, 2}, {0, 2, 3}};
  for (const auto& f : faces) {
    body += '\3';
    for (int i : f) put(&i, 4);
  }
  return body;
}

void plySeeds(const fs::path& dir) {
  write(dir / "quad_ascii.ply", std::string("ply\nformat ascii 1.0\ncomment lvox seed\n") +
                                    kPlyHeader + "0 0 0\n2 0 0\n2 2 0\n0 2 0\n3 0 1 2\n3 0 2 3\n");
  write(dir / "quad_polygon_ascii.ply", std::string("ply\nformat ascii 1.0\n") + kPlyHeader +
                                            "0 0 0\n2 0 0\n2 2 0\n0 2 0\n4 0 1 2 3\n3 0 2 3\n");
  write(dir / "quad_binary_le.ply",
        std::string("ply\nformat binary_little_endian 1.0\n") + kPlyHeader + binaryPlyBody(false));
  write(dir / "quad_binary_be.ply",
        std::string("ply\nformat binary_big_endian 1.0\n") + kPlyHeader + binaryPlyBody(true));
}

void objSeeds(const fs::path& dir) {
  // OBJ, a NUL, then the MTL (harnesses.cpp writes the MTL as m.mtl beside the OBJ).
  const std::string mtl = "newmtl white\nKd 0.8 0.8 0.8\nnewmtl lamp\nKd 0 0 0\nKe 4 4 4\n";
  write(dir / "quad_mtl.obj", std::string("mtllib m.mtl\nv 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\n"
                                          "vn 0 0 1\nvt 0 0\no quad\nusemtl white\n"
                                          "f 1/1/1 2/1/1 3/1/1 4/1/1\nusemtl lamp\nf -1 -2 -3\n") +
                                  '\0' + mtl);
  write(dir / "triangle.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
}

void exrSeeds(const fs::path& dir) {
  lvox::Image rgb(3, 2);
  for (size_t i = 0; i < rgb.pixels.size(); ++i)
    rgb.pixels[i] = lvox::RGB(0.25f * static_cast<float>(i), 1.0f, 2.0f);
  lvox::writeExr((dir / "rgb_float.exr").string(), rgb, false, {{"lvox.spp", "4"}});
  lvox::writeExr((dir / "rgb_half.exr").string(), rgb, true);
}

void vdbSeeds(const fs::path& dir) {
  openvdb::initialize();
  // A few voxels, one negative (clamped with a warning) and one 8^3 tile of the tree.
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("density");
  grid->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
  auto acc = grid->getAccessor();
  acc.setValue(openvdb::Coord(0, 0, 0), 1.0f);
  acc.setValue(openvdb::Coord(1, 0, 0), 0.5f);
  acc.setValue(openvdb::Coord(0, 2, 1), -0.25f);
  grid->tree().addTile(1, openvdb::Coord(16, 0, 0), 2.0f, true);
  auto other = openvdb::Vec3SGrid::create();
  other->setName("velocity");
  fs::create_directories(dir);
  const auto write = [&](const char* name, const openvdb::GridPtrVec& grids, uint32_t codec) {
    openvdb::io::File file((dir / name).string());
    file.setCompression(codec);
    file.write(grids);
    file.close();
  };
  // Only the active-mask compression: no zlib or blosc stream, so mutations reach values.
  write("density_small.vdb", {grid, other}, openvdb::io::COMPRESS_ACTIVE_MASK);
  // The density alone (under libFuzzer's 16 kB) with OpenVDB's two codecs, so mutations
  // reach the compressed blocks of the nodes and the leaves (docs/hardening.md).
  write("density_zip.vdb", {grid}, openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK);
  write("density_blosc.vdb", {grid},
        openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: lvox_make_fuzz_seeds SEEDS_DIR\n";
    return 2;
  }
  const fs::path root = argv[1];
  plySeeds(root / "ply");
  objSeeds(root / "obj");
  fs::create_directories(root / "exr");
  exrSeeds(root / "exr");
  vdbSeeds(root / "vdb");
  return 0;
}
