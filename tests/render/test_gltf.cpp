// glTF 2.0 through assimp: a file written here (two meshes under node transforms, a
// base-colour texture, an emissive material, a camera) renders exactly as its OBJ twin.
#include <gtest/gtest.h>

#include <cstring>

#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"
#include "textured_scenes.h"

namespace lvox {
namespace {

using namespace lvox::test;

// A quad [-1, 1]^2 at z = 0 (normal +z); glTF texture coordinates start at the image's
// top-left corner, OBJ ones at its bottom-left: v_gltf = 1 - v_obj.
void writeQuadBin(const fs::path& path) {
  const float positions[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const float normals[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  const float uvs[8] = {0, 1, 1, 1, 1, 0, 0, 0};
  const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
  std::string bytes(140, '\0');
  std::memcpy(bytes.data(), positions, 48);
  std::memcpy(bytes.data() + 48, normals, 48);
  std::memcpy(bytes.data() + 96, uvs, 32);
  std::memcpy(bytes.data() + 128, indices, 12);
  writeFile(path, bytes);
}

// Node 0: the textured quad scaled by (1/2, 1/2, 1), moved by (1/4, -1/4, 0); node 1: a
// lamp (base colour 1/2, emissive (1, 1/2, 1/4)) scaled by 1/8, moved to (-5/8, 5/8, 1/2);
// node 2: a camera at (0, 0, 10) looking down -z. Dyadic numbers keep the transformed
// vertices exact, so the twin is bit for bit the same geometry.
const char* kGltf = R"({
 "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1, 2]}],
 "nodes": [{"mesh": 0, "scale": [0.5, 0.5, 1], "translation": [0.25, -0.25, 0]},
           {"mesh": 1, "scale": [0.125, 0.125, 1], "translation": [-0.625, 0.625, 0.5]},
           {"camera": 0, "translation": [0, 0, 10]}],
 "cameras": [{"type": "perspective",
              "perspective": {"yfov": 0.19933730476, "aspectRatio": 1.0, "znear": 0.1, "zfar": 100}}],
 "meshes": [
   {"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]},
   {"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 3, "material": 1}]}],
 "materials": [
   {"name": "tex", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
   {"name": "lamp", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]},
    "emissiveFactor": [1, 0.5, 0.25]}],
 "textures": [{"source": 0}], "images": [{"uri": "blocks.png"}],
 "buffers": [{"uri": "quad.bin", "byteLength": 140}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                 {"buffer": 0, "byteOffset": 48, "byteLength": 48},
                 {"buffer": 0, "byteOffset": 96, "byteLength": 32},
                 {"buffer": 0, "byteOffset": 128, "byteLength": 12}],
 "accessors": [
   {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
   {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
   {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
   {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}]
})";

void writeObjTwin(const fs::path& dir) {
  writeFile(dir / "twin.mtl",
            "newmtl tex\nmap_Kd blocks.png\nnewmtl lamp\nKd 0.5 0.5 0.5\nKe 1 0.5 0.25\n");
  writeFile(dir / "twin.obj",
            "mtllib twin.mtl\n"
            "v -0.25 -0.75 0\nv 0.75 -0.75 0\nv 0.75 0.25 0\nv -0.25 0.25 0\n"
            "v -0.75 0.5 0.5\nv -0.5 0.5 0.5\nv -0.5 0.75 0.5\nv -0.75 0.75 0.5\n"
            "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
            "usemtl tex\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n"
            "usemtl lamp\nf 5//1 6//1 7//1\nf 5//1 7//1 8//1\n");
}

void writeFiles(const fs::path& dir) {
  std::vector<uint8_t> rgb(8 * 8 * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<uint8_t>((i * 37) % 251);
  writeTexturePng(dir / "blocks.png", 8, 8, rgb);
  writeQuadBin(dir / "quad.bin");
  writeFile(dir / "quad.gltf", kGltf);
  writeObjTwin(dir);
}

std::string scene(const std::string& shape, bool withCamera) {
  std::string s = "{";
  if (withCamera) s += R"("camera": )" + topCamera(48) + ",";
  return s + R"("render": {"spp": 4, "max_bounces": 3, "area_light_samples": 4},
    "shapes": [{"type": ")" +
         shape + R"(", "file": ")" + (shape == "gltf" ? "quad.gltf" : "twin.obj") +
         R"("}],
    "lights": [{"type": "directional", "direction": [0.6, 0, -0.8], "irradiance": 3}]})";
}

Scene load(const fs::path& dir, const std::string& name, const std::string& text) {
  writeFile(dir / name, text);
  return loadScene((dir / name).string());
}

TEST(Gltf, RendersExactlyAsItsObjTwin) {
  const fs::path dir = tempDir();
  writeFiles(dir);
  const Scene gltf = load(dir, "gltf.json", scene("gltf", true));
  const Scene obj = load(dir, "obj.json", scene("obj", true));
  ASSERT_EQ(gltf.world.mesh.triangleCount(), 4u);
  for (Mode mode : {Mode::kDirect, Mode::kMc}) {
    Scene a = gltf, b = obj;
    a.render.mode = b.render.mode = mode;
    Report ra, rb;
    const Image ia = renderScene(a.job(), ra), ib = renderScene(b.job(), rb);
    double lit = 0.0;
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 48; ++x)
        for (int c = 0; c < 3; ++c) {
          // Same triangles, texels, emission and random streams: the same image.
          EXPECT_EQ(ia.at(x, y)[c], ib.at(x, y)[c]) << modeName(mode) << " " << x << "," << y;
          lit += ia.at(x, y)[c];
        }
    EXPECT_GT(lit, 48.0) << "the scene is not black";
  }
  // The lamp is emissive: its pixels show Ke (1, 0.5, 0.25) plus the sunlight its base
  // colour 1/2 reflects, 0.5 * 3 * 0.8 / pi.
  Scene direct = gltf;
  direct.render.mode = Mode::kDirect;
  Report report;
  const Image image = renderScene(direct.job(), report);
  // Its corners (-3/4, 3/4) and (-1/2, 1/2) at height 1/2 project to pixels 5.05 and 11.4.
  const float reflected = 0.5f * 3.0f * 0.8f / kPi;
  EXPECT_NEAR(image.at(8, 8)[0], 1.0f + reflected, 1e-5f);
  EXPECT_NEAR(image.at(8, 8)[2], 0.25f + reflected, 1e-5f);
}

TEST(Gltf, SceneWithoutCameraTakesTheFilesCamera) {
  const fs::path dir = tempDir();
  writeFiles(dir);
  const Scene s = load(dir, "gltf.json", scene("gltf", false));
  const Camera& cam = s.world.camera;
  EXPECT_NEAR(cam.position.z, 10.0f, 1e-6f);
  const Vec3 forward = normalize(cam.lookAt - cam.position);
  EXPECT_NEAR(forward.z, -1.0f, 1e-6f);
  EXPECT_NEAR(cam.up.y, 1.0f, 1e-6f);
  EXPECT_NEAR(cam.vfovDeg, 0.19933730476 * 180.0 / 3.14159265358979, 1e-4);
  EXPECT_EQ(cam.width, cam.height);  // aspect ratio 1
  // And without either, the scene names what is missing.
  writeFile(dir / "none.json", R"({"shapes": [{"type": "obj", "file": "twin.obj"}]})");
  EXPECT_THROW(loadScene((dir / "none.json").string()), InputError);
}

}  // namespace
}  // namespace lvox
