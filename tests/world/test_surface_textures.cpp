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

// The quad [0, 1]^2 (z = 0) with texture coordinates equal to (x, y), of the material `mtl`
// (whose maps the caller has written into dir).
World quadOf(const fs::path& dir, const std::string& mtl) {
  writeFile(dir / "q.mtl", "newmtl m\n" + mtl);
  writeFile(dir / "q.obj",
            "mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
            "usemtl m\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
  World world;
  loadObj((dir / "q.obj").string(), "file", Transform{}, std::nullopt, world);
  return world;
}

// A 4 x 4 PNG whose texel (x, y) (row y from the top) has red 60 x + 10 and green 60 y + 10,
// on the quad.
World texturedQuad(const fs::path& dir, const std::string& extraMtl = "") {
  std::vector<uint8_t> rgb(4 * 4 * 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      rgb[3 * (4 * y + x)] = static_cast<uint8_t>(60 * x + 10);
      rgb[3 * (4 * y + x) + 1] = static_cast<uint8_t>(60 * y + 10);
      rgb[3 * (4 * y + x) + 2] = 0;
    }
  writePngRgb8((dir / "t.png").string(), 4, 4, rgb);
  return quadOf(dir, "Kd 0.2 0.2 0.2\nmap_Kd t.png\n" + extraMtl);
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
        // map_Kd replaces Kd: the texel itself, decoded from sRGB (and stored as a half
        // float: rounded by at most 2^-11 of itself).
        const float red = srgbByteToLinear(60 * tx + 10), green = srgbByteToLinear(60 * ty + 10);
        EXPECT_NEAR(got.x, red, red / 2048.0f) << tx << "," << ty;
        EXPECT_NEAR(got.y, green, green / 2048.0f) << tx << "," << ty;
        EXPECT_EQ(got.z, 0.0f);
      }
}

TEST(SurfaceTextures, FilteredLookupBlendsNeighboursAndAveragesWideFootprints) {
  const World world = texturedQuad(tempDir());
  const SurfaceTextures textures(world);
  uint32_t tri;
  Vec2 b;
  // Halfway between the centres of texels (1, 0) and (2, 0) the bilinear lookup is their
  // mean in linear light (0.142; the decoded mean of their encoded values 70 and 130 would
  // be 0.127).
  locate(world, 0.5f, 1.0f - 0.125f, tri, b);
  RGB got = textures.albedo(tri, b.x, b.y, Vec3(0.0f), Vec3(0.0f));
  const float blend = 0.5f * (srgbByteToLinear(70) + srgbByteToLinear(130));
  EXPECT_NEAR(got.x, blend, blend / 2048.0f);
  // A footprint as wide as the whole texture averages every red value in linear light
  // (0.171; the decoded mean of the encoded values, 100, would be 0.127).
  locate(world, 0.5f, 0.5f, tri, b);
  got = textures.albedo(tri, b.x, b.y, Vec3(1.0f, 0, 0), Vec3(0, 1.0f, 0));
  float mean = 0.0f;
  for (int x = 0; x < 4; ++x) mean += 0.25f * srgbByteToLinear(60 * x + 10);
  EXPECT_NEAR(got.x, mean, 0.02f);
  EXPECT_NEAR(got.y, mean, 0.02f);
}

// A size x size grey PNG whose texel (x, y) is white where white(x, y), else black, on the
// quad.
template <class White>
World twoToneQuad(const fs::path& dir, int size, White&& white) {
  std::vector<uint8_t> rgb(static_cast<size_t>(size * size * 3));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      for (int c = 0; c < 3; ++c)
        rgb[static_cast<size_t>(3 * (size * y + x) + c)] = white(x, y) ? 255 : 0;
  writePngRgb8((dir / "t.png").string(), size, size, rgb);
  return quadOf(dir, "Kd 1 1 1\nmap_Kd t.png\n");
}

// A surfel's albedo is the mean reflectance over its disk, in linear light. On a
// checkerboard of black and white squares that is 1/2, where decoding the mean of the
// encoded texels (the filtered lookup over the disk that surfels took until stop 51) gives
// 0.22: on Sponza that made the surfels 0.7 % too dark, and the indirect light, where the
// darkening compounds over the bounces, 0.8 %. 49 disks of radius 0.2 (about 30 squares of 32
// texels each), 16 bilinear point lookups each: the points fall on white with probability 1/2, so
// the mean of 784 has a standard deviation below 0.018 (the texel-wide seams, where bilinear
// blends black and white, in linear light since stop 52, average to 1/2 as well). So the mean is
// within 0.06 of 1/2, 3.3 standard deviations.
TEST(SurfaceTextures, AlbedoOverADiskIsTheMeanInLinearLight) {
  const World world =
      twoToneQuad(tempDir(), 512, [](int x, int y) { return (x / 32 + y / 32) % 2 == 0; });
  const SurfaceTextures textures(world);
  double sum = 0.0;
  int disks = 0;
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j) {
      uint32_t tri;
      Vec2 b;
      // Disks that cross the triangle's edges average the part on it: still 1/2.
      const float x = 0.33f + 0.05f * static_cast<float>(i),
                  y = 0.2f + 0.02f * static_cast<float>(j);
      locate(world, x, y, tri, b);
      sum += textures.albedoOverDisk(tri, b.x, b.y, 0.2f).x;
      ++disks;
    }
  EXPECT_NEAR(sum / disks, 0.5, 0.06);
  uint32_t tri;
  Vec2 b;
  locate(world, 0.6f, 0.3f, tri, b);
  const float radius = 0.2f;
  // A filtered lookup (MIP levels) over the disk's square: 1/2 as well, since the texture
  // reaches OpenImageIO decoded (src/world/linear_texture_input.h). Until stop 52 it averaged
  // the encoded texels and decoded their mean, 0.22.
  const RGB filtered =
      textures.albedo(tri, b.x, b.y, Vec3(2.0f * radius, 0, 0), Vec3(0, 2.0f * radius, 0));
  EXPECT_NEAR(filtered.x, 0.5f, 0.05f);
}

// Texture coordinates mean nothing off a triangle (an atlas packs other surfaces there), so
// a disk that crosses the triangle's edge averages the part on the triangle. The lower
// right triangle of the quad is white and the rest of the texture black: a disk across the
// diagonal is white, where a filtered lookup over the disk blends in the black half.
TEST(SurfaceTextures, AlbedoOverADiskKeepsToItsTriangle) {
  // Rows run down the image: texel row y holds v = 1 - (y + 0.5) / 64.
  const World world = twoToneQuad(tempDir(), 64, [](int x, int y) { return 63 - y <= x; });
  const SurfaceTextures textures(world);
  uint32_t tri;
  Vec2 b;
  locate(world, 0.55f, 0.45f, tri, b);
  ASSERT_EQ(tri, 0u);
  // All 16 points but those within a texel of the diagonal (a staircase) read white.
  EXPECT_GT(textures.albedoOverDisk(tri, b.x, b.y, 0.3f).x, 0.85f);
  EXPECT_LT(textures.albedo(tri, b.x, b.y, Vec3(0.6f, 0, 0), Vec3(0, 0.6f, 0)).x, 0.7f);
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

// A mask's coverage is no light: an 8-bit mask is read as stored and cuts below 1/2 of its
// range, whether or not the same image is also an albedo map (which reaches OpenImageIO
// decoded, so its cut moves to the decoded 1/2). Grey 100 (0.39 as stored, 0.13 decoded)
// is a hole, grey 140 (0.55, 0.26) is not; with the decoded values against 1/2 both would be.
TEST(SurfaceTextures, EncodedMaskCutsWhereItsStoredValueIsOneHalf) {
  for (const std::string mtl : {"Kd 1 1 1\nmap_d m.png\n", "map_Kd m.png\nmap_d m.png\n"}) {
    const fs::path dir = tempDir();
    std::vector<uint8_t> rgb(8 * 8 * 3);
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x)
        for (int c = 0; c < 3; ++c)
          rgb[static_cast<size_t>(3 * (8 * y + x) + c)] = x < 4 ? 100 : 140;
    writePngRgb8((dir / "m.png").string(), 8, 8, rgb);
    const World world = quadOf(dir, mtl);
    const SurfaceTextures textures(world);
    uint32_t tri;
    Vec2 b;
    locate(world, 0.2f, 0.7f, tri, b);
    EXPECT_TRUE(textures.isCutAway(tri, b.x, b.y)) << mtl;
    locate(world, 0.8f, 0.3f, tri, b);
    EXPECT_FALSE(textures.isCutAway(tri, b.x, b.y)) << mtl;
  }
}

// A float albedo map holds what it holds: a NaN texel reflects nothing, a negative one
// nothing, one above 1 all (an albedo is within [0, 1]); no NaN reaches the light.
TEST(SurfaceTextures, FloatTexelsOutsideZeroToOneAreClamped) {
  const fs::path dir = tempDir();
  // A PFM (little-endian floats, RGB, one row), written by hand: lvox's own EXR writer
  // would replace the NaN and the negative value.
  const float texels[9] = {std::nanf(""), std::nanf(""), std::nanf(""), -0.5f, -0.5f,
                           -0.5f,         2.0f,          2.0f,          2.0f};
  std::string pfm = "PF\n3 1\n-1.0\n";
  pfm.append(reinterpret_cast<const char*>(texels), sizeof texels);
  writeFile(dir / "t.pfm", pfm);
  const World world = quadOf(dir, "map_Kd t.pfm\n");
  const SurfaceTextures textures(world, TextureFilter::kNearest);
  const float expected[3] = {0.0f, 0.0f, 1.0f};
  for (int tx = 0; tx < 3; ++tx) {
    uint32_t tri;
    Vec2 b;
    locate(world, (static_cast<float>(tx) + 0.5f) / 3.0f, 0.5f, tri, b);
    const RGB got = textures.albedo(tri, b.x, b.y, Vec3(0.0f), Vec3(0.0f));
    for (int c = 0; c < 3; ++c) EXPECT_EQ(got[c], expected[tx]) << tx << " " << c;
  }
}

}  // namespace
}  // namespace lvox
