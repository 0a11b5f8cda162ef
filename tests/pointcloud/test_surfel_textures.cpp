// Surfels on textured triangles: none on a cut-out's holes, and each carries the albedo
// its disk averages (for the interreflection).
#include <gtest/gtest.h>

#include "pointcloud/surfel_sampler.h"
#include "src/core/image.h"
#include "src/core/image_io.h"
#include "src/world/mesh_loader.h"
#include "src/world/surface_textures.h"
#include "test_util.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

// The quad [0, 1]^2 with an EXR albedo map (left half 0.9, right half 0.1) and, if
// `cutout`, a mask cutting away its lower half (v < 1/2).
World quad(const fs::path& dir, bool cutout) {
  Image albedo(64, 4), mask(1, 2);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 64; ++x) albedo.at(x, y) = RGB(x < 32 ? 0.9f : 0.1f);
  mask.at(0, 0) = RGB(1.0f);  // top row: opaque
  mask.at(0, 1) = RGB(0.0f);
  writeExr((dir / "albedo.exr").string(), albedo);
  writeExr((dir / "mask.exr").string(), mask);
  test::writeFile(dir / "q.mtl", std::string("newmtl m\nmap_Kd albedo.exr\n") +
                                     (cutout ? "map_d mask.exr\n" : ""));
  test::writeFile(dir / "q.obj",
                  "mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                  "vt 0 1\nusemtl m\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
  World world;
  loadObj((dir / "q.obj").string(), "file", Transform{}, std::nullopt, world);
  return world;
}

TEST(SurfelTextures, NoSurfelOnACutAwayTexel) {
  const fs::path dir = test::tempDir();
  UniformSurfelSettings settings;
  settings.spacing = 0.02f;
  const World whole = quad(dir, false);
  const SurfaceTextures wholeTextures(whole);
  const size_t all =
      sampleSurfelsUniform(whole.mesh, whole.materials, settings, &wholeTextures).size();
  const World cut = quad(dir, true);
  const SurfaceTextures textures(cut);
  const SurfelSet surfels = sampleSurfelsUniform(cut.mesh, cut.materials, settings, &textures);
  // The mask's bilinear lookup crosses 1/2 at v = 1/2 (and at the periodic seam v = 0):
  // the upper half keeps its surfels, give or take one lattice row.
  EXPECT_NEAR(static_cast<double>(surfels.size()) / static_cast<double>(all), 0.5, 0.03);
  for (size_t i = 0; i < surfels.size(); ++i)
    EXPECT_GE(surfels.position[i].y, 0.5f - 1e-3f) << "surfel " << i << " on a hole";
}

TEST(SurfelTextures, SurfelsCarryTheirDisksAverageAlbedo) {
  const fs::path dir = test::tempDir();
  const World world = quad(dir, false);
  const SurfaceTextures textures(world);
  UniformSurfelSettings settings;
  settings.spacing = 0.05f;
  const SurfelSet surfels = sampleSurfelsUniform(world.mesh, world.materials, settings, &textures);
  ASSERT_GT(surfels.size(), 100u);
  double mean = 0.0;
  for (size_t i = 0; i < surfels.size(); ++i) {
    const float x = surfels.position[i].x, a = surfels.albedo[i].x;
    // Two disk radii (0.065) from the edge at x = 1/2 and the periodic one at x = 0, 1, a
    // disk sees one side only; nearer, it sees both.
    if (x > 0.15f && x < 0.35f) {
      EXPECT_NEAR(a, 0.9f, 0.01f) << x;
    } else if (x > 0.65f && x < 0.85f) {
      EXPECT_NEAR(a, 0.1f, 0.01f) << x;
    }
    EXPECT_GE(a, 0.1f - 1e-4f);
    EXPECT_LE(a, 0.9f + 1e-4f);
    mean += a;
  }
  // Uniform surfels over the quad: the mean albedo is the texture's, 0.5.
  EXPECT_NEAR(mean / static_cast<double>(surfels.size()), 0.5, 0.03);
}

}  // namespace
}  // namespace lvox
