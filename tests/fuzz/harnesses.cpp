#include "harnesses.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "src/core/image_io.h"
#include "src/world/mesh_loader.h"
#include "src/scene/scene_loader.h"
#include "volume/media/vdb_loader.h"

namespace lvox::fuzz {
namespace {

namespace fs = std::filesystem;

// The readers take file names, so each input is written to a file first, in one
// directory per process (ctest runs the replay tests in parallel), removed at exit.
class ScratchDir {
 public:
  ScratchDir() {
    const char* base = std::getenv("TMPDIR");
    std::string pattern = std::string(base && *base ? base : "/tmp") + "/lvox-fuzz-XXXXXX";
    if (!mkdtemp(pattern.data())) std::abort();  // no scratch space: nothing can be checked
    dir_ = pattern;
    // A small valid mesh beside the scene file, so that scene inputs can reach the mesh
    // loaders through relative file names.
    std::ofstream(dir_ / "a.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::ofstream(dir_ / "a.ply") << "ply\nformat ascii 1.0\nelement vertex 3\n"
                                     "property float x\nproperty float y\nproperty float z\n"
                                     "element face 1\nproperty list uchar int vertex_indices\n"
                                     "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  std::string write(const std::string& name, std::string_view bytes) const {
    const fs::path path = dir_ / name;
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return path.string();
  }

 private:
  fs::path dir_;
};

const ScratchDir& scratch() {
  static const ScratchDir dir;
  return dir;
}

std::string_view view(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// A scene with one material, as the PLY loader expects its caller to have.
World meshWorld() {
  World world;
  world.materials.push_back(Material{"m", RGB(0.5f), RGB(0.0f)});
  return world;
}

}  // namespace

void sceneJson(const uint8_t* data, size_t size) {
  const std::string text(view(data, size));
  (void)parseScene(text, scratch().write("scene.json", text));
}

void objMtl(const uint8_t* data, size_t size) {
  // One input holds both files, split at the first NUL: the OBJ can say "mtllib m.mtl".
  const std::string_view bytes = view(data, size);
  const size_t nul = bytes.find('\0');
  const std::string_view obj = bytes.substr(0, nul);
  const std::string_view mtl = nul == std::string_view::npos ? "" : bytes.substr(nul + 1);
  scratch().write("m.mtl", mtl);
  World world = meshWorld();
  (void)loadObj(scratch().write("fuzz.obj", obj), "shapes[0].file", Transform(), std::nullopt,
                world);
}

void ply(const uint8_t* data, size_t size) {
  World world = meshWorld();
  (void)loadPly(scratch().write("fuzz.ply", view(data, size)), "shapes[0].file", Transform(), 0,
                world);
}

void vdb(const uint8_t* data, size_t size) {
  GridLoadReport report;
  (void)loadVdbGrid(scratch().write("fuzz.vdb", view(data, size)), "density", Transform(),
                    "media[0].file", report);
}

void exr(const uint8_t* data, size_t size) {
  ImageMetadata metadata;
  (void)readExr(scratch().write("fuzz.exr", view(data, size)), &metadata);
}

std::span<const Harness> harnesses() {
  static constexpr Harness kAll[] = {
      {"scene", sceneJson}, {"obj", objMtl}, {"ply", ply}, {"vdb", vdb}, {"exr", exr}};
  return kAll;
}

}  // namespace lvox::fuzz
