#pragma once
// Small textured scenes the texture tests write into their temporary directory: a unit
// quad seen straight down by a camera whose image spans exactly the quad, so pixel (px, py)
// of an N x N image sees texture coordinates (px / N, 1 - py / N).
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/core/image_io.h"
#include "test_util.h"

namespace lvox::test {

namespace fs = std::filesystem;

// An OBJ quad z = height over [x0, x1] x [y0, y1] with texture coordinates over [0, 1]^2,
// optional per-vertex normal `normal` on every vertex, and MTL material `material`.
inline void writeQuadObj(const fs::path& obj, const std::string& mtl, const std::string& material,
                         float x0, float y0, float x1, float y1, float height,
                         const std::string& normal = "") {
  std::ostringstream s;
  s << "mtllib " << mtl << "\n";
  s << "v " << x0 << " " << y0 << " " << height << "\nv " << x1 << " " << y0 << " " << height
    << "\nv " << x1 << " " << y1 << " " << height << "\nv " << x0 << " " << y1 << " " << height
    << "\n";
  s << "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
  if (!normal.empty()) s << "vn " << normal << "\n";
  s << "usemtl " << material << "\n";
  if (normal.empty())
    s << "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  else
    s << "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";
  writeFile(obj, s.str());
}

// The camera that sees [-1, 1]^2 at z = 0 edge to edge from (0, 0, 10), N x N pixels.
inline std::string topCamera(int n) {
  std::ostringstream s;
  s << R"({"position": [0, 0, 10], "look_at": [0, 0, 0], "up": [0, 1, 0], "vfov_deg": )"
    << 2.0 * std::atan(0.1) * 180.0 / 3.14159265358979323846 << R"(, "width": )" << n
    << R"(, "height": )" << n << "}";
  return s.str();
}

// A scene of OBJ files under one directional light of irradiance E travelling along `dir`.
inline std::string objScene(int n, const std::vector<std::string>& objs, float irradiance,
                            const std::string& dir = "[0, 0, -1]", int spp = 4) {
  std::ostringstream s;
  s << R"({"camera": )" << topCamera(n) << R"(, "render": {"spp": )" << spp
    << R"(, "max_bounces": 4}, "shapes": [)";
  for (size_t i = 0; i < objs.size(); ++i)
    s << (i ? "," : "") << R"({"type": "obj", "file": ")" << objs[i] << R"("})";
  s << R"(], "lights": [{"type": "directional", "direction": )" << dir << R"(, "irradiance": )"
    << irradiance << "}]}";
  return s.str();
}

// An 8-bit (sRGB-encoded) PNG texture, rows top to bottom.
inline void writeTexturePng(const fs::path& path, int w, int h, const std::vector<uint8_t>& rgb) {
  writePngRgb8(path.string(), w, h, rgb);
}

// The textures' decoded texels are stored as half floats (src/world/linear_texture_input.h):
// each is rounded by at most 2^-11 of itself (half an ulp of an 11-bit significand, at the
// bottom of its binade); bilinear blends of such texels keep that bound. 2^-10 leaves room
// for the float arithmetic after the lookup.
constexpr float kHalfRounding = 1.0f / 1024.0f;

inline float srgbByteToLinear(uint8_t b) {
  const float v = static_cast<float>(b) / 255.0f;
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

}  // namespace lvox::test
