// Textures (MTL map_Kd, map_d), texture coordinates and smooth normals in every mode,
// against closed forms: a Lambertian point of albedo rho under a directional light of
// irradiance E at incidence theta has radiance rho E cos(theta) / pi.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "src/core/error.h"
#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"
#include "textured_scenes.h"

namespace lvox {
namespace {

using namespace lvox::test;

Image render(const Scene& scene, Mode mode) {
  Scene s = scene;
  s.render.mode = mode;
  Report report;
  return renderScene(s.job(), report);
}

Scene loadText(const fs::path& dir, const std::string& text) {
  writeFile(dir / "scene.json", text);
  return loadScene((dir / "scene.json").string());
}

// 8 x 8 PNG of 4 x 4 blocks of 2 x 2 equal texels: bilinear lookups inside a block's
// central half return the block's texel exactly.
std::vector<uint8_t> blockTexture(uint8_t (*colour)(int bx, int by, int c)) {
  std::vector<uint8_t> rgb(8 * 8 * 3);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c) rgb[3 * (8 * y + x) + c] = colour(x / 2, y / 2, c);
  return rgb;
}

uint8_t blockColour(int bx, int by, int c) {
  return static_cast<uint8_t>(20 + 50 * bx + 9 * by + 30 * c);
}

constexpr float kIrradiance = 3.0f;
const float kCos = 0.8f;  // the light travels along (0.6, 0, -0.8)

TEST(Textures, TexelAlbedoTimesIrradianceInEveryMode) {
  const fs::path dir = tempDir();
  writeTexturePng(dir / "blocks.png", 8, 8, blockTexture(blockColour));
  writeFile(dir / "quad.mtl", "newmtl tex\nKd 0.3 0.3 0.3\nmap_Kd blocks.png\n");
  writeQuadObj(dir / "quad.obj", "quad.mtl", "tex", -1, -1, 1, 1, 0);
  const Scene scene = loadText(dir, objScene(32, {"quad.obj"}, kIrradiance, "[0.6, 0, -0.8]"));
  for (Mode mode : {Mode::kDirect, Mode::kMc, Mode::kPcb, Mode::kPcbSurfels}) {
    const Image image = render(scene, mode);
    // Pixels 3 and 4 of each 8-pixel block lie in its texels' central half.
    for (int by = 0; by < 4; ++by)
      for (int bx = 0; bx < 4; ++bx)
        for (int px : {8 * bx + 3, 8 * bx + 4})
          for (int py : {8 * by + 3, 8 * by + 4})
            for (int c = 0; c < 3; ++c) {
              const float expected =
                  srgbByteToLinear(blockColour(bx, by, c)) * kIrradiance * kCos / kPi;
              // Only direct light (one quad, no environment): exact up to the texels'
              // rounding to half floats.
              EXPECT_NEAR(image.at(px, py)[c], expected, kHalfRounding * expected + 1e-6f)
                  << modeName(mode) << " pixel " << px << "," << py << " channel " << c;
            }
  }
}

// The unit quad textured with `texture` (written into dir), under 32 x 32 pixels of 8 x 8
// texels each: the largest relative difference of any pixel, in any of the direct, MC and
// pcb modes, from a texture whose mean is 1/2. Box-filtered mip levels of an even checker
// are exactly 1/2; 1 % covers the trilinear blend and the pixel jitter.
void expectEveryPixelAveragesToOneHalf(const fs::path& dir, const std::string& texture) {
  writeFile(dir / "quad.mtl", "newmtl tex\nmap_Kd " + texture + "\n");
  writeQuadObj(dir / "quad.obj", "quad.mtl", "tex", -1, -1, 1, 1, 0);
  const Scene scene = loadText(dir, objScene(32, {"quad.obj"}, kIrradiance, "[0.6, 0, -0.8]"));
  const float expected = 0.5f * kIrradiance * kCos / kPi;
  for (Mode mode : {Mode::kDirect, Mode::kMc, Mode::kPcb}) {
    const Image image = render(scene, mode);
    double worst = 0.0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x)
        worst = std::max(worst, std::abs(double(image.at(x, y)[1]) / expected - 1.0));
    EXPECT_LT(worst, 0.01) << texture << " " << modeName(mode);
  }
}

// A 256 x 256 checker of single texels (linear 0.9 and 0.1, float EXR): the mip-mapped
// lookup averages it to 0.5, where a point lookup would alias between 0.1 and 0.9.
TEST(Textures, FilteredLookupAveragesTheFootprint) {
  const fs::path dir = tempDir();
  Image checker(256, 256);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) checker.at(x, y) = RGB((x + y) % 2 ? 0.9f : 0.1f);
  writeExr((dir / "checker.exr").string(), checker);
  expectEveryPixelAveragesToOneHalf(dir, "checker.exr");
}

// The same with an 8-bit PNG of single black and white texels: sRGB-encoded, so the linear
// mean is 1/2, and what a filtered lookup of the encoded bytes gives (the decoded mean, 0.214)
// is 57 % darker. The texture reaches OpenImageIO decoded (src/world/linear_texture_input.h),
// so its mip levels average light.
TEST(Textures, FilteredLookupAveragesAnEncodedTextureInLinearLight) {
  const fs::path dir = tempDir();
  std::vector<uint8_t> rgb(256 * 256 * 3);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x)
      for (int c = 0; c < 3; ++c) rgb[3 * (256 * y + x) + c] = (x + y) % 2 ? 255 : 0;
  writeTexturePng(dir / "checker.png", 256, 256, rgb);
  expectEveryPixelAveragesToOneHalf(dir, "checker.png");
}

// An occluder quad at height 1 over [-0.9, -0.1] x [-0.4, 0.4] whose map_d cuts away its
// lower half (v < 1/2, y < 0); light along (1, 0, -1)/sqrt(2) throws its shadow one unit
// to +x, onto [0.1, 0.9] x [0, 0.4] of a white receiver at z = 0, outside the occluder's
// image. The shadow's area, summed from the pixels' darkness, is 0.8 x 0.4.
double shadowArea(const fs::path& dir, Mode mode, bool cutout) {
  Image mask(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) mask.at(x, y) = RGB(y < 4 ? 1.0f : 0.0f);  // top rows opaque
  writeExr((dir / "mask.exr").string(), mask);
  writeFile(dir / "scene.mtl",
            std::string("newmtl white\nKd 1 1 1\nnewmtl leaf\nKd 0.5 0.5 0.5\n") +
                (cutout ? "map_d mask.exr\n" : ""));
  writeQuadObj(dir / "receiver.obj", "scene.mtl", "white", -1, -1, 1, 1, 0);
  writeQuadObj(dir / "leaf.obj", "scene.mtl", "leaf", -0.9f, -0.4f, -0.1f, 0.4f, 1);
  const int n = 64;
  const Scene scene = loadText(dir, objScene(n, {"receiver.obj", "leaf.obj"}, kIrradiance,
                                             "[0.70710678, 0, -0.70710678]", 16));
  const Image image = render(scene, mode);
  const float lit = kIrradiance * 0.70710678f / kPi;
  const double pixelArea = (2.0 / n) * (2.0 / n);
  double area = 0.0;
  for (int y = 0; y < n; ++y)
    for (int x = n / 2; x < n; ++x)  // x > 0: the receiver only
      area += (1.0 - std::clamp(double(image.at(x, y)[0]) / lit, 0.0, 1.0)) * pixelArea;
  return area;
}

TEST(Textures, CutoutCastsTheShadowOfItsOpaquePart) {
  const fs::path dir = tempDir();
  for (Mode mode : {Mode::kDirect, Mode::kMc, Mode::kPcb}) {
    // pcb and mc add light the receiver gets back from the leaf's underside: none here
    // (the leaf faces the receiver's lit side only from above its shadow); the pixel
    // jitter of 16 samples leaves about 1 % on the shadow's edges.
    EXPECT_NEAR(shadowArea(dir, mode, true), 0.8 * 0.4, 0.02 * 0.32) << modeName(mode);
    EXPECT_NEAR(shadowArea(dir, mode, false), 0.8 * 0.8, 0.02 * 0.64) << modeName(mode);
  }
}

// Shading normals tilted 36.87 degrees (n_s = (0.6, 0, 0.8)) on a flat quad, light straight
// down: cos(theta) becomes 0.8 and nothing else changes: the same pixels are covered.
TEST(Textures, SmoothNormalsChangeShadingNotGeometry) {
  const fs::path dir = tempDir();
  writeFile(dir / "quad.mtl", "newmtl grey\nKd 0.5 0.5 0.5\n");
  // A quad smaller than the image, so coverage has an edge to compare.
  writeQuadObj(dir / "flat.obj", "quad.mtl", "grey", -0.55f, -0.3f, 0.45f, 0.6f, 0);
  writeQuadObj(dir / "smooth.obj", "quad.mtl", "grey", -0.55f, -0.3f, 0.45f, 0.6f, 0, "0.6 0 0.8");
  const Scene flat = loadText(dir, objScene(32, {"flat.obj"}, kIrradiance));
  const Scene smooth = loadText(dir, objScene(32, {"smooth.obj"}, kIrradiance));
  for (Mode mode : {Mode::kDirect, Mode::kMc, Mode::kPcb}) {
    const Image a = render(flat, mode), b = render(smooth, mode);
    int covered = 0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        const float fa = a.at(x, y)[0], fb = b.at(x, y)[0];
        EXPECT_EQ(fa > 0.0f, fb > 0.0f) << "coverage differs at " << x << "," << y;
        if (fa > 0.0f) {
          ++covered;
          // Shading scales by cos(theta_s) / cos(theta_g) = 0.8 everywhere, edges included.
          EXPECT_NEAR(fb, 0.8f * fa, 1e-4f * fa) << modeName(mode) << " " << x << "," << y;
        }
      }
    EXPECT_GT(covered, 32 * 32 / 5);
    EXPECT_NEAR(a.at(10, 10)[0], 0.5f * kIrradiance / kPi, 1e-5f);
  }
}

// The same tilt under a constant sky: the irradiance of a sky of radiance L on a plane
// whose cosine is taken about a normal tilted by theta, the directions below the
// geometric plane cut off, is pi L (1 + cos theta) / 2 (the sky's view factor of a
// tilted plane): 0.9 of the flat quad's. pcb's sky comes through its final gathers, whose
// rays must be cosine-weighted about the shading normal as MC's bounces and light samples
// are (until stop 56 they took the geometric normal: 1.0 here, and on Sponza's smooth
// arches and columns the indirect light was off by up to 10 % in patches).
TEST(Textures, GathersWeighTheSkyByTheShadingNormal) {
  const fs::path dir = tempDir();
  writeFile(dir / "quad.mtl", "newmtl grey\nKd 0.5 0.5 0.5\n");
  writeQuadObj(dir / "flat.obj", "quad.mtl", "grey", -3, -3, 3, 3, 0);
  writeQuadObj(dir / "smooth.obj", "quad.mtl", "grey", -3, -3, 3, 3, 0, "0.6 0 0.8");
  auto scene = [&](const std::string& obj) {
    return loadText(
        dir,
        R"({"camera": )" + topCamera(8) +
            R"(, "render": {"spp": 16, "max_bounces": 4}, "shapes": [{"type": "obj", "file": ")" +
            obj + R"("}], "lights": [{"type": "environment", "radiance": 1}],
                             "pointcloud": {"gather_samples": 512}})");
  };
  const Scene flat = scene("flat.obj"), smooth = scene("smooth.obj");
  auto mean = [](const Image& image) {
    double sum = 0.0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) sum += image.at(x, y)[0];
    return sum / (image.width * image.height);
  };
  const double expectedFlat = 0.5, expectedSmooth = 0.5 * (1.0 + 0.8) / 2.0;
  for (Mode mode : {Mode::kMc, Mode::kPcb}) {
    const double a = mean(render(flat, mode)), b = mean(render(smooth, mode));
    std::printf("%s: flat %.4f (%.4f), smooth %.4f (%.4f)\n", std::string(modeName(mode)).c_str(),
                a, expectedFlat, b, expectedSmooth);
    // 64 pixels x 16 spp x 512 gather rays (pcb) or 16 sky samples (MC): well under 1 %.
    EXPECT_NEAR(a, expectedFlat, 0.01 * expectedFlat) << modeName(mode);
    EXPECT_NEAR(b, expectedSmooth, 0.01 * expectedSmooth) << modeName(mode);
  }
}

// The same texel check for a PLY with u, v coordinates and a scene material's
// "albedo_texture" (times its "albedo" 0.5).
TEST(Textures, PlyCoordinatesWithASceneMaterialTexture) {
  const fs::path dir = tempDir();
  writeTexturePng(dir / "blocks.png", 8, 8, blockTexture(blockColour));
  writeFile(dir / "quad.ply",
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
            "property float z\nproperty float u\nproperty float v\nelement face 1\n"
            "property list uchar int vertex_indices\nend_header\n"
            "-1 -1 0 0 0\n1 -1 0 1 0\n1 1 0 1 1\n-1 1 0 0 1\n4 0 1 2 3\n");
  std::string text = objScene(32, {}, kIrradiance, "[0.6, 0, -0.8]");
  text.replace(text.find(R"("shapes": [])"), 12,
               R"("materials": {"tex": {"albedo_texture": "blocks.png", "albedo": 0.5}},
                  "shapes": [{"type": "ply", "file": "quad.ply", "material": "tex"}])");
  const Scene scene = loadText(dir, text);
  const Image image = render(scene, Mode::kDirect);
  for (int b : {0, 3})
    for (int c = 0; c < 3; ++c) {
      const float expected =
          0.5f * srgbByteToLinear(blockColour(b, 3 - b, c)) * kIrradiance * kCos / kPi;
      EXPECT_NEAR(image.at(8 * b + 4, 8 * (3 - b) + 4)[c], expected, kHalfRounding * expected);
    }
}

TEST(Textures, MissingTextureIsOneLineNamingTheMtlAndTheMap) {
  const fs::path dir = tempDir();
  writeFile(dir / "quad.mtl", "newmtl tex\nmap_Kd no_such_texture.png\n");
  writeQuadObj(dir / "quad.obj", "quad.mtl", "tex", -1, -1, 1, 1, 0);
  writeFile(dir / "scene.json", objScene(8, {"quad.obj"}, 1.0f));
  try {
    loadScene((dir / "scene.json").string());
    FAIL() << "a missing texture was accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find((dir / "quad.mtl").string()), std::string::npos) << msg;
    EXPECT_NE(msg.find("map_Kd"), std::string::npos) << msg;
    EXPECT_NE(msg.find("no_such_texture.png"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

TEST(Textures, TexturesAreInputsOfTheScene) {
  const fs::path dir = tempDir();
  writeTexturePng(dir / "blocks.png", 8, 8, blockTexture(blockColour));
  writeFile(dir / "quad.mtl", "newmtl tex\nmap_Kd blocks.png\n");
  writeQuadObj(dir / "quad.obj", "quad.mtl", "tex", -1, -1, 1, 1, 0);
  const Scene scene = loadText(dir, objScene(8, {"quad.obj"}, 1.0f));
  const std::string texture = (dir / "blocks.png").lexically_normal().string();
  EXPECT_NE(std::find(scene.inputFiles.begin(), scene.inputFiles.end(), texture),
            scene.inputFiles.end());
}

}  // namespace
}  // namespace lvox
