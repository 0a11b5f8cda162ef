// Texture lookups on a loaded OBJ quad: texture coordinates from `vt`, nearest and filtered
// lookups, sRGB decoding of 8-bit images, cut-out masks.
#include <gtest/gtest.h>

#include <cmath>

#include "src/core/image.h"
#include "src/core/image_io.h"
#include "src/world/mesh_loader.h"
#include "src/world/surface_textures.h"
#include "test_util.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;
using test::tempDir;
using test::writeFile;

float srgbByteToLinear(int b) {
  const float v = static_cast<float>(b) / 255.0f;
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

// A 4 x 4 PNG whose texel (x, y) (row y from the top) has red 60 x + 10 and green 60 y + 10,
// on the quad [0, 1]^2 (z = 0) with texture coordinates equal to (x, y).
World texturedQuad(const fs::path& dir, const std::string& extraMtl = "") {
  std::vector<uint8_t> rgb(4 * 4 * 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      rgb[3 * (4 * y + x)] = static_cast<uint8_t>(60 * x + 10);
      rgb[3 * (4 * y + x) + 1] = static_cast<uint8_t>(60 * y + 10);
      rgb[3 * (4 * y + x) + 2] = 0;
    }
  writePngRgb8((dir / "t.png").string(), 4, 4, rgb);
  writeFile(dir / "q.mtl", "newmtl m\nKd 0.2 0.2 0.2\nmap_Kd t.png\n" + extraMtl);
  writeFile(dir / "q.obj",
            "mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
            "usemtl m\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
  World world;
  loadObj((dir / "q.obj").string(), "file", Transform{}, std::nullopt, world);
  return world;
}

// The triangle of the quad holding point (x, y) and the barycentrics there.
void locate(const World& world, float x, float y, uint32_t& tri, Vec2& b) {
  tri = y <= x ? 0 : 1;
  b = world.mesh.barycentricOf(tri, Vec3(x, y, 0));
}

TEST(SurfaceTextures, NearestLookupReturnsTheTexelUnderThePoint) {
  const World world = texturedQuad(tempDir());
  ASSERT_EQ(world.textures.size(), 1u);
  const SurfaceTextures textures(world, TextureFilter::kNearest);
  for (int ty = 0; ty < 4; ++ty)
    for (int tx = 0; tx < 4; ++tx)
      // Near a texel's corner, where a bilinear lookup would blend in its neighbours.
      for (float f : {0.05f, 0.95f}) {
        const float u = (static_cast<float>(tx) + f) / 4.0f;
        const float v = 1.0f - (static_cast<float>(ty) + f) / 4.0f;  // rows run down
        uint32_t tri;
        Vec2 b;
        locate(world, u, v, tri, b);
        const RGB got = textures.albedo(tri, b.x, b.y, Vec3(0.0f), Vec3(0.0f));
        // map_Kd replaces Kd: the texel itself, decoded from sRGB.
        EXPECT_NEAR(got.x, srgbByteToLinear(60 * tx + 10), 1e-5f) << tx << "," << ty;
        EXPECT_NEAR(got.y, srgbByteToLinear(60 * ty + 10), 1e-5f) << tx << "," << ty;
        EXPECT_EQ(got.z, 0.0f);
      }
}

TEST(SurfaceTextures, FilteredLookupBlendsNeighboursAndAveragesWideFootprints) {
  const World world = texturedQuad(tempDir());
  const SurfaceTextures textures(world);
  uint32_t tri;
  Vec2 b;
  // Halfway between the centres of texels (1, 0) and (2, 0) the bilinear lookup is their
  // mean (in the encoded values, which the sRGB decode follows).
  locate(world, 0.5f, 1.0f - 0.125f, tri, b);
  RGB got = textures.albedo(tri, b.x, b.y, Vec3(0.0f), Vec3(0.0f));
  EXPECT_NEAR(got.x, srgbByteToLinear(100), 2e-3f);
  // A footprint as wide as the whole texture averages every red value (70, 100 in sRGB
  // steps around the mean 100): well away from any single texel's.
  locate(world, 0.5f, 0.5f, tri, b);
  got = textures.albedo(tri, b.x, b.y, Vec3(1.0f, 0, 0), Vec3(0, 1.0f, 0));
  EXPECT_NEAR(got.x, srgbByteToLinear(100), 0.02f);
  EXPECT_NEAR(got.y, srgbByteToLinear(100), 0.02f);
}

TEST(SurfaceTextures, CutoutMaskReadsItsFirstChannelAgainstOneHalf) {
  const fs::path dir = tempDir();
  Image mask(2, 1);
  mask.at(0, 0) = RGB(0.0f);  // left half cut away
  mask.at(1, 0) = RGB(1.0f);
  writeExr((dir / "mask.exr").string(), mask);
  const World world = texturedQuad(dir, "map_d mask.exr\n");
  const SurfaceTextures textures(world, TextureFilter::kNearest);
  EXPECT_TRUE(textures.anyCutouts());
  uint32_t tri;
  Vec2 b;
  locate(world, 0.2f, 0.7f, tri, b);
  EXPECT_TRUE(textures.isCutAway(tri, b.x, b.y));
  locate(world, 0.8f, 0.3f, tri, b);
  EXPECT_FALSE(textures.isCutAway(tri, b.x, b.y));
}

}  // namespace
}  // namespace lvox
