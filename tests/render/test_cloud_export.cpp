// --export-cloud (src/render/cloud_export.h): a cloud written as PLY and as an OpenVDB
// PointDataGrid reads back with its element count and every attribute, through our own
// reading of the PLY layout, through assimp (an independent PLY reader) and through OpenVDB;
// a render's exported cloud is the cloud the render used.
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>

#include <assimp/Importer.hpp>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "src/core/image_io.h"
#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"
#include "test_util.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

ExportedCloud handMade() {
  ExportedCloud c;
  c.add(CloudPointKind::kSurfel, Vec3(0, 0, 0), Vec3(0, 1, 0), 0.05f, RGB(0.5f, 0.25f, 0.125f),
        RGB(0.0f), 0.0f);
  c.add(CloudPointKind::kSurfel, Vec3(1, 0, 0), Vec3(0, 0, -1), 0.07f, RGB(2.0f, 1.0f, 0.0f),
        RGB(0.1f, 0.2f, 0.3f), 0.0f);
  c.add(CloudPointKind::kLvoxel, Vec3(0.5f, 2, 0.25f), Vec3(0.0f), 0.1f, RGB(0.3f), RGB(0.3f),
        4.5f);
  return c;
}

struct PlyRecord {
  float f[14];
  uint8_t kind, rgb[3];
};

// Our reading of the layout the header declares: 14 floats and 4 bytes per vertex.
std::vector<PlyRecord> readPly(const std::string& path, std::string& header) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  size_t count = 0;
  while (std::getline(in, line) && line != "end_header") {
    header += line + "\n";
    if (line.rfind("element vertex ", 0) == 0) count = std::stoul(line.substr(15));
  }
  std::vector<PlyRecord> records(count);
  for (PlyRecord& r : records) {
    in.read(reinterpret_cast<char*>(r.f), sizeof r.f);
    in.read(reinterpret_cast<char*>(&r.kind), 1);
    in.read(reinterpret_cast<char*>(r.rgb), 3);
  }
  EXPECT_TRUE(in.good());
  EXPECT_EQ(in.peek(), std::char_traits<char>::eof());  // nothing after the last vertex
  return records;
}

TEST(CloudExport, PlyReadsBackEveryAttribute) {
  const ExportedCloud c = handMade();
  const fs::path path = test::tempDir() / "cloud.ply";
  writeCloud(path.string(), c);
  std::string header;
  const std::vector<PlyRecord> r = readPly(path.string(), header);
  EXPECT_NE(header.find("format binary_little_endian 1.0"), std::string::npos);
  ASSERT_EQ(r.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(r[i].f[a], c.position[i][a]);
      EXPECT_EQ(r[i].f[3 + a], c.normal[i][a]);
      EXPECT_EQ(r[i].f[7 + a], c.radiance[i][a]);
      EXPECT_EQ(r[i].f[10 + a], c.radianceBack[i][a]);
      EXPECT_EQ(r[i].rgb[a], toneMap(c.radiance[i][a]));
    }
    EXPECT_EQ(r[i].f[6], c.radius[i]);
    EXPECT_EQ(r[i].f[13], c.sigmaT[i]);
    EXPECT_EQ(r[i].kind, static_cast<uint8_t>(c.kind[i]));
  }
  // assimp, as MeshLab-like readers do, finds the points, their normals and colours.
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path.string(), 0);
  ASSERT_NE(scene, nullptr) << importer.GetErrorString();
  ASSERT_EQ(scene->mNumMeshes, 1u);
  const aiMesh* mesh = scene->mMeshes[0];
  ASSERT_EQ(mesh->mNumVertices, 3u);
  ASSERT_TRUE(mesh->HasNormals());
  ASSERT_TRUE(mesh->HasVertexColors(0));
  for (unsigned i = 0; i < 3; ++i) {
    EXPECT_EQ(mesh->mVertices[i].x, c.position[i].x);
    EXPECT_EQ(mesh->mVertices[i].y, c.position[i].y);
    EXPECT_EQ(mesh->mNormals[i].z, c.normal[i].z);
    EXPECT_NEAR(mesh->mColors[0][i].r * 255.0f, toneMap(c.radiance[i].x), 1e-3f);
  }
}

TEST(CloudExport, VdbPointDataGridReadsBackEveryAttribute) {
  const ExportedCloud c = handMade();
  const fs::path path = test::tempDir() / "cloud.vdb";
  writeCloud(path.string(), c);
  openvdb::initialize();
  openvdb::io::File file(path.string());
  file.open();
  auto grid = openvdb::gridPtrCast<openvdb::points::PointDataGrid>(file.readGrid("points"));
  file.close();
  ASSERT_TRUE(grid);
  EXPECT_EQ(openvdb::points::pointCount(grid->tree()), 3u);
  // Points come back bucketed by voxel: match them by position.
  std::map<std::tuple<float, float, float>, size_t> byPosition;
  for (size_t i = 0; i < c.size(); ++i)
    byPosition[{c.position[i].x, c.position[i].y, c.position[i].z}] = i;
  size_t seen = 0;
  for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
    using openvdb::points::AttributeHandle;
    AttributeHandle<openvdb::Vec3f> p(leaf->constAttributeArray("P"));
    AttributeHandle<openvdb::Vec3f> n(leaf->constAttributeArray("N"));
    AttributeHandle<openvdb::Vec3f> cd(leaf->constAttributeArray("Cd"));
    AttributeHandle<openvdb::Vec3f> back(leaf->constAttributeArray("radiance_back"));
    AttributeHandle<float> pscale(leaf->constAttributeArray("pscale"));
    AttributeHandle<float> sigmaT(leaf->constAttributeArray("sigma_t"));
    AttributeHandle<int32_t> kind(leaf->constAttributeArray("kind"));
    for (auto idx = leaf->beginIndexOn(); idx; ++idx) {
      const openvdb::Vec3f world =
          grid->transform().indexToWorld(p.get(*idx) + idx.getCoord().asVec3d());
      size_t i = c.size();
      for (const auto& [key, value] : byPosition)
        if (std::abs(std::get<0>(key) - world.x()) < 1e-5f &&
            std::abs(std::get<1>(key) - world.y()) < 1e-5f &&
            std::abs(std::get<2>(key) - world.z()) < 1e-5f)
          i = value;
      ASSERT_LT(i, c.size()) << "a point at an unknown position";
      for (int a = 0; a < 3; ++a) {
        EXPECT_EQ(n.get(*idx)[a], c.normal[i][a]);
        EXPECT_EQ(cd.get(*idx)[a], c.radiance[i][a]);
        EXPECT_EQ(back.get(*idx)[a], c.radianceBack[i][a]);
      }
      EXPECT_EQ(pscale.get(*idx), c.radius[i]);
      EXPECT_EQ(sigmaT.get(*idx), c.sigmaT[i]);
      EXPECT_EQ(kind.get(*idx), static_cast<int32_t>(c.kind[i]));
      ++seen;
    }
  }
  EXPECT_EQ(seen, 3u);
}

// The cloud of a render: every surfel and lvoxel the report counts, with the radiance the
// render's gathers read (lit surfels, glowing fog).
TEST(CloudExport, ARendersCloudIsTheCloudItUsed) {
  Scene scene = parseScene(R"({
    "camera": {"position": [0, 1.5, 4], "look_at": [0, 0.3, 0], "vfov_deg": 45, "width": 8, "height": 8},
    "materials": {"white": {"albedo": 0.7}},
    "shapes": [{"type": "quad", "corners": [[-2,0,-2],[2,0,-2],[2,0,2],[-2,0,2]], "material": "white"}],
    "lights": [{"type": "directional", "direction": [0.3, -1, -0.2], "irradiance": 3}],
    "media": [{"type": "homogeneous", "min": [-1, 0, -1], "max": [1, 1, 1], "sigma_a": 0.2, "sigma_s": 0.3}],
    "pointcloud": {"target_surfels": 2000, "lvoxel_spacing": 0.25}})",
                           "/tmp/cloud-export-test.json");
  scene.render.mode = Mode::kPcb;
  ExportedCloud cloud;
  RenderPlan plan;
  plan.cloudOut = &cloud;
  Report report;
  renderScene(scene.job(), plan, report);
  const uint64_t surfels = report.count("surfels"), lvoxels = report.count("lvoxels");
  ASSERT_GT(surfels, 1000u);
  EXPECT_EQ(lvoxels, 8u * 4u * 8u);
  ASSERT_EQ(cloud.size(), surfels + lvoxels);
  double surfelLight = 0.0, lvoxelLight = 0.0;
  for (size_t i = 0; i < cloud.size(); ++i)
    (cloud.kind[i] == CloudPointKind::kSurfel ? surfelLight : lvoxelLight) +=
        cloud.radiance[i].x + cloud.radianceBack[i].x;  // the lit side, whichever it is
  // The lit floor under the sun: albedo E cos / pi = 0.7 x 3 x 0.96 / pi = 0.64 at most,
  // less where the fog shades it.
  EXPECT_GT(surfelLight / static_cast<double>(surfels), 0.1);
  EXPECT_LT(surfelLight / static_cast<double>(surfels), 0.7);
  EXPECT_GT(lvoxelLight, 0.0);
  EXPECT_EQ(cloud.sigmaT.back(), 0.5f);  // sigma_a + sigma_s of the fog
}

}  // namespace
}  // namespace lvox
