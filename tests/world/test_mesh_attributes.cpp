// Texture coordinates and shading normals read from OBJ (vt, vn) and PLY (u, v / s, t;
// nx, ny, nz), transformed with the shape.
#include <gtest/gtest.h>

#include "src/world/mesh_loader.h"
#include "test_util.h"

namespace lvox {
namespace {

TEST(MeshAttributes, PlyTextureCoordinatesAndNormals) {
  const auto dir = test::tempDir();
  for (const char* uvNames : {"u v", "s t"}) {
    const std::string u = std::string(uvNames).substr(0, 1), v = std::string(uvNames).substr(2);
    test::writeFile(dir / "t.ply",
                    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
                    "property float " +
                        u + "\nproperty float " + v +
                        "\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                        "0 0 0 0 0 1 0.25 0.5\n1 0 0 0.6 0 0.8 0.75 0.5\n0 1 0 0 0 1 0.25 1\n"
                        "3 0 1 2\n");
    World world;
    // A rotation by 90 degrees about z turns the normal (0.6, 0, 0.8) into (0, 0.6, 0.8).
    loadPly((dir / "t.ply").string(), "file", Transform::rotate(Vec3(0, 0, 1), 90.0f), 0, world);
    ASSERT_EQ(world.mesh.triangleCount(), 1u);
    ASSERT_EQ(world.mesh.uvs.size(), 3u) << uvNames;
    ASSERT_EQ(world.mesh.normals.size(), 3u);
    // Vertex order may be rotated by the loader: find vertex (1, 0, 0) -> (0, 1, 0).
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = world.mesh.vertex(0, k);
      const Vec2 uv = world.mesh.uvs[world.mesh.indices[k]];
      const Vec3 n = world.mesh.normals[world.mesh.indices[k]];
      if (std::abs(p.y - 1.0f) < 1e-5f && std::abs(p.x) < 1e-5f) {
        EXPECT_NEAR(uv.x, 0.75f, 1e-6f);
        EXPECT_NEAR(uv.y, 0.5f, 1e-6f);
        EXPECT_NEAR(n.x, 0.0f, 1e-5f);
        EXPECT_NEAR(n.y, 0.6f, 1e-5f);
        EXPECT_NEAR(n.z, 0.8f, 1e-5f);
      }
    }
  }
}

TEST(MeshAttributes, ObjWithoutAttributesKeepsNone) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  World world;
  loadObj((dir / "t.obj").string(), "file", Transform{}, std::nullopt, world);
  // Untextured, flat meshes carry no attribute arrays: renders of them are unchanged.
  EXPECT_TRUE(world.mesh.uvs.empty());
  EXPECT_TRUE(world.mesh.normals.empty());
}

TEST(MeshAttributes, MixedMeshesFillTheGapsFlat) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  test::writeFile(dir / "smooth.obj",
                  "v 0 0 1\nv 1 0 1\nv 0 1 1\nvn 0.6 0 0.8\nvt 0.5 0.5\nf 1/1/1 2/1/1 3/1/1\n");
  World world;
  loadObj((dir / "flat.obj").string(), "file", Transform{}, std::nullopt, world);
  loadObj((dir / "smooth.obj").string(), "file", Transform{}, std::nullopt, world);
  ASSERT_EQ(world.mesh.normals.size(), 6u);
  ASSERT_EQ(world.mesh.uvs.size(), 6u);
  EXPECT_NEAR(world.mesh.shadingNormalAt(0, 0.3f, 0.3f).z, 1.0f, 1e-6f);  // geometric
  EXPECT_NEAR(world.mesh.shadingNormalAt(1, 0.3f, 0.3f).x, 0.6f, 1e-6f);  // the file's
  EXPECT_EQ(world.mesh.uvAt(0, 0.3f, 0.3f), Vec2(0.0f));
  EXPECT_NEAR(world.mesh.uvAt(1, 0.3f, 0.3f).x, 0.5f, 1e-6f);
}

}  // namespace
}  // namespace lvox
