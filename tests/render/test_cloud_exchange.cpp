// The pieces of the point cloud built across ranks (src/render/cloud_exchange.h), in one
// process: slices of the triangles sampled apart and concatenated through their bytes,
// then probed for burial in ranges, are the set one process samples and keeps, field by
// field; the bytes are checked on receipt.
#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>

#include "pointcloud/buried_surfels.h"
#include "pointcloud/scenes.h"
#include "pointcloud/surfel_sampler.h"
#include "src/core/byte_blocks.h"
#include "src/render/cloud_exchange.h"

namespace lvox {
namespace {

template <class T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

void expectSameSurfels(const SurfelSet& a, const SurfelSet& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(sameBits(a.position, b.position));
  EXPECT_TRUE(sameBits(a.normal, b.normal));
  EXPECT_TRUE(sameBits(a.radius, b.radius));
  EXPECT_TRUE(sameBits(a.albedo, b.albedo));
  EXPECT_TRUE(sameBits(a.triangle, b.triangle));
  EXPECT_TRUE(sameBits(a.clip, b.clip));
  EXPECT_TRUE(sameBits(a.enclosedSides, b.enclosedSides));
  EXPECT_EQ(a.radiusScale, b.radiusScale);
  EXPECT_EQ(a.radianceFront.size(), a.size());
  EXPECT_EQ(a.radianceBack.size(), a.size());
}

// A wall with a slab pushed into it (buried faces) and a sphere (small triangles).
TriangleMesh testMesh() {
  TriangleMesh mesh;
  test::addBox(mesh, Vec3(0, 0, 0), Vec3(1, 1, 0.3f), 0);
  test::addBox(mesh, Vec3(0.2f, 0.4f, -0.5f), Vec3(0.8f, 0.5f, 0.15f), 0);
  test::addSphere(mesh, Vec3(0.5f, 1.5f, 0.0f), 0.3f, 16, 32, 0);
  return mesh;
}

TEST(CloudExchange, SlicesSampledAndProbedApartAreTheWholeSet) {
  const TriangleMesh mesh = testMesh();
  const std::vector<Material> materials{Material{}};
  const RayTracer tracer(mesh);
  const UniformSurfelSettings base{0.02f, 1.15f, 5};
  const BuriedSurfelSettings burial{2.0f, 16, 5, {}};
  SurfelSet whole = sampleSurfelsUniform(mesh, materials, base);
  const size_t removed = removeBuriedSurfels(whole, tracer, burial);
  ASSERT_GT(removed, 0u);
  for (int ranks : {1, 2, 3, 7}) {
    const std::vector<size_t> first = triangleSlices(mesh, ranks);
    ASSERT_EQ(first.size(), static_cast<size_t>(ranks) + 1);
    EXPECT_EQ(first.front(), 0u);
    EXPECT_EQ(first.back(), mesh.triangleCount());
    SurfelSet joined;
    for (int r = 0; r < ranks; ++r) {
      ASSERT_LE(first[r], first[r + 1]);
      UniformSurfelSettings s = base;
      s.firstTriangle = first[r];
      s.endTriangle = first[r + 1];
      const SurfelSet slice = sampleSurfelsUniform(mesh, materials, s);
      appendSurfelsFromBytes(surfelsToBytes(slice), "rank " + std::to_string(r), joined);
    }
    // Each rank probes its range of the joined set; the marks are then everyone's.
    for (int r = 0; r < ranks; ++r)
      markEnclosedSides(joined, tracer, burial, joined.size() * r / ranks,
                        joined.size() * (r + 1) / ranks);
    EXPECT_EQ(removeEnclosedSurfels(joined), removed);
    SCOPED_TRACE(ranks);
    expectSameSurfels(joined, whole);
  }
}

TEST(CloudExchange, SlicesHaveAboutEqualArea) {
  TriangleMesh mesh;
  test::addSphere(mesh, Vec3(0, 0, 0), 1.0f, 32, 64, 0);
  auto area = [&](size_t t) {
    return 0.5 * length(cross(mesh.vertex(t, 1) - mesh.vertex(t, 0),
                              mesh.vertex(t, 2) - mesh.vertex(t, 0)));
  };
  double total = 0.0;
  for (size_t t = 0; t < mesh.triangleCount(); ++t) total += area(t);
  const std::vector<size_t> first = triangleSlices(mesh, 4);
  for (int r = 0; r < 4; ++r) {
    double share = 0.0;
    for (size_t t = first[r]; t < first[r + 1]; ++t) share += area(t);
    EXPECT_NEAR(share / total, 0.25, 0.01) << r;  // up to one of 4096 triangles
  }
}

TEST(CloudExchange, DamagedBytesAreAnErrorNamingTheSender) {
  const TriangleMesh mesh = testMesh();
  const SurfelSet s = sampleSurfelsUniform(mesh, {Material{}}, {0.05f, 1.15f, 5});
  const std::string bytes = surfelsToBytes(s);
  auto error = [&](const std::string& damaged) {
    SurfelSet out;
    try {
      appendSurfelsFromBytes(damaged, "rank 3", out);
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(out.size(), 0u);
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // Truncated in transit.
  EXPECT_NE(error(bytes.substr(0, bytes.size() / 2)).find("from rank 3"), std::string::npos);
  // Trailing bytes.
  EXPECT_NE(error(bytes + "x").find("bytes left after the last field"), std::string::npos);
  // Another layout number (bytes 4-7).
  std::string other = bytes;
  other[4] = static_cast<char>(other[4] + 1);
  EXPECT_NE(error(other).find("block layout 2, expected 1"), std::string::npos);
  // Another element size for the positions (after magic, layout, radius scale, count).
  std::string wide = bytes;
  wide[4 + 4 + 4 + 8] = 16;
  EXPECT_NE(error(wide).find("surfel positions: elements of 16 bytes, expected 12"),
            std::string::npos)
      << error(wide);
  EXPECT_NE(error("").find("from rank 3"), std::string::npos);
}

TEST(ByteBlocks, ValuesAndArraysRoundTrip) {
  ByteBlockWriter w(9);
  w.value(uint64_t(42));
  w.array(std::vector<float>{1.0f, -2.5f});
  w.array(std::vector<uint8_t>{});
  const std::string bytes = w.take();
  ByteBlockReader r(bytes, 9, "rank 1");
  EXPECT_EQ(r.value<uint64_t>(), 42u);
  std::vector<float> f;
  r.array(f, "floats");
  EXPECT_EQ(f, (std::vector<float>{1.0f, -2.5f}));
  std::vector<uint8_t> none{1, 2};
  r.array(none, "bytes");
  EXPECT_TRUE(none.empty());
  r.finish();
  EXPECT_THROW(r.value<uint8_t>(), std::runtime_error);
}

}  // namespace
}  // namespace lvox
