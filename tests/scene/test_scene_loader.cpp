#include <gtest/gtest.h>

#include "src/core/error.h"
#include "src/scene/scene_loader.h"
#include "test_util.h"

namespace lvox {
namespace {

const char* kMinimal = R"({
  "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "vfov_deg": 40, "width": 64, "height": 32},
  "materials": {"white": {"albedo": [0.5, 0.6, 0.7]}},
  "shapes": [{"type": "quad", "corners": [[-1,0,-1],[1,0,-1],[1,0,1],[-1,0,1]], "material": "white"}],
  "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2}]
})";

// Expects parseScene to throw an InputError whose message contains every fragment.
void expectError(const std::string& text, std::initializer_list<std::string> fragments) {
  try {
    parseScene(text, "/tmp/scene.json");
    FAIL() << "no error for: " << text;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("/tmp/scene.json", 0), 0u) << msg;  // the file comes first
    for (const std::string& f : fragments) EXPECT_NE(msg.find(f), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
  }
}

std::string withField(const std::string& replaceFrom, const std::string& replaceTo) {
  std::string s = kMinimal;
  const size_t at = s.find(replaceFrom);
  EXPECT_NE(at, std::string::npos) << replaceFrom;
  return s.replace(at, replaceFrom.size(), replaceTo);
}

TEST(SceneLoader, MinimalScene) {
  const Scene scene = parseScene(kMinimal, "/tmp/scene.json");
  EXPECT_EQ(scene.world.camera.width, 64);
  EXPECT_EQ(scene.world.camera.height, 32);
  EXPECT_EQ(scene.world.mesh.triangleCount(), 2u);
  ASSERT_EQ(scene.world.lights.size(), 1u);
  EXPECT_FLOAT_EQ(scene.world.lights[0].intensity.y, 2.0f);
  EXPECT_FLOAT_EQ(scene.world.materials[0].albedo.z, 0.7f);
}

TEST(SceneLoader, MalformedJsonNamesLineAndColumn) {
  expectError("{\n  \"camera\": {\n    \"position\": [0, 1,, 5]\n  }\n}",
              {"line 3", "malformed JSON"});
}

TEST(SceneLoader, MissingFile) {
  EXPECT_THROW(loadScene("/nonexistent/scene.json"), InputError);
  try {
    loadScene("/nonexistent/scene.json");
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("No such file"), std::string::npos) << e.what();
  }
}

TEST(SceneLoader, WrongType) {
  expectError(withField("\"width\": 64", "\"width\": \"wide\""), {"camera.width", "integer"});
  expectError(withField("\"vfov_deg\": 40", "\"vfov_deg\": [40]"), {"camera.vfov_deg", "number"});
}

TEST(SceneLoader, NonFiniteNumbers) {
  // JSON has no NaN literal; the parser rejects it, and 1e400 overflows to infinity.
  expectError(withField("\"irradiance\": 2", "\"irradiance\": NaN"), {"malformed JSON"});
  expectError(withField("\"vfov_deg\": 40", "\"vfov_deg\": 1e400"), {"overflow"});
}

TEST(SceneLoader, BadValues) {
  expectError(withField("\"width\": 64", "\"width\": -64"), {"camera.width", "outside"});
  expectError(withField("\"height\": 32", "\"height\": 0"), {"camera.height"});
  expectError(withField("\"vfov_deg\": 40", "\"vfov_deg\": 180"), {"camera.vfov_deg"});
  expectError(withField("[0.5, 0.6, 0.7]", "[0.5, 1.6, 0.7]"), {"materials.white.albedo"});
  expectError(withField("\"irradiance\": 2", "\"irradiance\": -2"), {"lights[0].irradiance"});
  expectError(withField("\"direction\": [0, -1, 0]", "\"direction\": [0, 0, 0]"),
              {"lights[0].direction"});
}

TEST(SceneLoader, PointCloudSettingsAreRangeChecked) {
  auto withPointCloud = [](const std::string& settings) {
    return withField("\"lights\"", "\"pointcloud\": {" + settings + "}, \"lights\"");
  };
  const Scene scene =
      parseScene(withPointCloud("\"gather_filter\": 2.5, \"burial_reach\": 0, \"bounces\": 200, "
                                "\"lvoxel_near_samples\": 48, \"lvoxel_near_reach\": 0"),
                 "/tmp/scene.json");
  EXPECT_FLOAT_EQ(scene.pointcloud.gatherFilter, 2.5f);
  EXPECT_FLOAT_EQ(scene.pointcloud.burialReach, 0.0f);
  EXPECT_EQ(scene.pointcloud.bounces, 200);
  EXPECT_EQ(scene.pointcloud.lvoxelNearSamples, 48);
  EXPECT_FLOAT_EQ(scene.pointcloud.lvoxelNearReach, 0.0f);
  expectError(withPointCloud("\"lvoxel_near_samples\": 0"),
              {"pointcloud.lvoxel_near_samples", "outside"});
  expectError(withPointCloud("\"lvoxel_near_reach\": -1"),
              {"pointcloud.lvoxel_near_reach", "outside"});
  expectError(withPointCloud("\"gather_filter\": 0.5"), {"pointcloud.gather_filter", "outside"});
  // "gather_samples": a count, or "auto" (the default: pointcloud_settings.h).
  EXPECT_EQ(parseScene(kMinimal, "/tmp/scene.json").pointcloud.gatherSamples, kAutoGatherSamples);
  EXPECT_EQ(parseScene(withPointCloud("\"gather_samples\": \"auto\""), "/tmp/scene.json")
                .pointcloud.gatherSamples,
            kAutoGatherSamples);
  EXPECT_EQ(parseScene(withPointCloud("\"gather_samples\": 96"), "/tmp/scene.json")
                .pointcloud.gatherSamples,
            96);
  expectError(withPointCloud("\"gather_samples\": \"many\""),
              {"pointcloud.gather_samples", "a count of rays or \"auto\"", "many"});
  expectError(withPointCloud("\"gather_samples\": true"),
              {"pointcloud.gather_samples", "a count of rays or \"auto\", got boolean"});
  expectError(withPointCloud("\"gather_samples\": null"),
              {"pointcloud.gather_samples", "a count of rays or \"auto\", got null"});
  expectError(withPointCloud("\"gather_samples\": 0"), {"pointcloud.gather_samples", "outside"});
  expectError(withPointCloud("\"gather_samples\": 2.5"), {"pointcloud.gather_samples", "integer"});
  EXPECT_EQ(parseScene(kMinimal, "/tmp/scene.json").pointcloud.gatherLightSamples, 0);
  // Under auto the light rays are a share of the 64 rays auto gives at least.
  EXPECT_EQ(parseScene(withPointCloud("\"gather_light_samples\": 63"), "/tmp/scene.json")
                .pointcloud.gatherLightSamples,
            63);
  expectError(withPointCloud("\"gather_light_samples\": 64"),
              {"pointcloud.gather_light_samples", "the 64 rays that \"gather_samples\": \"auto\""});
  EXPECT_EQ(parseScene(withPointCloud("\"gather_samples\": 32, \"gather_light_samples\": 8"),
                       "/tmp/scene.json")
                .pointcloud.gatherLightSamples,
            8);
  // A gather keeps at least one cosine ray: the sky and the media come by those alone.
  expectError(withPointCloud("\"gather_samples\": 16, \"gather_light_samples\": 16"),
              {"pointcloud.gather_light_samples", "less than gather_samples (16)"});
  expectError(withPointCloud("\"gather_light_samples\": -1"),
              {"pointcloud.gather_light_samples", "outside"});
  expectError(withPointCloud("\"gather_light_samples\": 8, \"gather_visibility\": \"cloud\""),
              {"pointcloud.gather_light_samples", "gather_visibility"});
  expectError(withPointCloud("\"burial_reach\": -1"), {"pointcloud.burial_reach", "outside"});
  expectError(withPointCloud("\"bounces\": 5000"), {"pointcloud.bounces", "outside"});
  expectError(withPointCloud("\"gather_visibility\": \"exact\""),
              {"pointcloud.gather_visibility", "exact"});
  EXPECT_FLOAT_EQ(parseScene(kMinimal, "/tmp/scene.json").pointcloud.hitLatticeStep, 0.7f);
  EXPECT_FLOAT_EQ(parseScene(withPointCloud("\"hit_lattice_step\": 0"), "/tmp/scene.json")
                      .pointcloud.hitLatticeStep,
                  0.0f);
  expectError(withPointCloud("\"hit_lattice_step\": -0.5"),
              {"pointcloud.hit_lattice_step", "outside"});
  expectError(withPointCloud("\"hit_lattice_step\": 20"),
              {"pointcloud.hit_lattice_step", "outside"});
  const Scene minimal = parseScene(kMinimal, "/tmp/scene.json");
  EXPECT_EQ(minimal.pointcloud.surfelLightSamples, 4);
  EXPECT_EQ(minimal.pointcloud.lvoxelLightSamples, 8);
  EXPECT_EQ(parseScene(withPointCloud("\"surfel_light_samples\": 64"), "/tmp/scene.json")
                .pointcloud.surfelLightSamples,
            64);
  expectError(withPointCloud("\"surfel_light_samples\": 0"),
              {"pointcloud.surfel_light_samples", "outside"});
  expectError(withPointCloud("\"lvoxel_light_samples\": 0"),
              {"pointcloud.lvoxel_light_samples", "outside"});
  expectError(withPointCloud("\"lvoxel_light_samples\": \"many\""),
              {"pointcloud.lvoxel_light_samples"});
  // A named setting: its default, another name it reads, and a name it refuses.
  auto expectChoice = [&](const std::string& key, auto field, auto byDefault,
                          const std::string& other, auto otherValue, const std::string& bad) {
    EXPECT_EQ(minimal.pointcloud.*field, byDefault) << key;
    EXPECT_EQ(parseScene(withPointCloud("\"" + key + "\": \"" + other + "\""), "/tmp/scene.json")
                      .pointcloud.*
                  field,
              otherValue)
        << key;
    expectError(withPointCloud("\"" + key + "\": \"" + bad + "\""), {"pointcloud." + key, bad});
  };
  expectChoice("lvoxel_light_blend", &PointCloudSettings::lvoxelLightBlend,
               LvoxelLightBlend::kExponential, "linear", LvoxelLightBlend::kLinear, "cubic");
  expectChoice("lvoxel_own_cube", &PointCloudSettings::lvoxelOwnCube, LvoxelOwnCube::kQuadrature,
               "rays", LvoxelOwnCube::kRays, "exact");
  expectChoice("lvoxel_extinction", &PointCloudSettings::lvoxelExtinction,
               LvoxelExtinction::kTransmittance, "mean", LvoxelExtinction::kMean, "median");
  expectChoice("camera_shadow_rays", &PointCloudSettings::cameraShadowRays,
               CameraShadowRays::kEdges, "none", CameraShadowRays::kNone, "some");
  expectChoice("camera_shadow_rays", &PointCloudSettings::cameraShadowRays,
               CameraShadowRays::kEdges, "all", CameraShadowRays::kAll, "every");
  expectChoice("indirect_shadow_media", &PointCloudSettings::indirectShadowMedia,
               IndirectShadowMedia::kCubes, "media", IndirectShadowMedia::kMedia, "voxels");
  expectChoice("bounce_tail", &PointCloudSettings::bounceTail, BounceTail::kGeometric, "none",
               BounceTail::kNone, "linear");
  expectChoice("gather_fit", &PointCloudSettings::gatherFit, GatherFit::kLinear, "constant",
               GatherFit::kConstant, "quadratic");
  expectChoice("surfel_gather_allocation", &PointCloudSettings::surfelGatherAllocation,
               SurfelRayAllocation::kUniform, "variance", SurfelRayAllocation::kVariance, "even");
  // The passes: at most 64 by default, stopped at 1e-3 of the light still to come; 0 runs
  // them all.
  EXPECT_EQ(minimal.pointcloud.bounces, 64);
  EXPECT_FLOAT_EQ(minimal.pointcloud.bounceTolerance, 1e-3f);
  EXPECT_FLOAT_EQ(parseScene(withPointCloud("\"bounce_tolerance\": 0"), "/tmp/scene.json")
                      .pointcloud.bounceTolerance,
                  0.0f);
  expectError(withPointCloud("\"bounce_tolerance\": -0.1"),
              {"pointcloud.bounce_tolerance", "outside"});
  expectError(withPointCloud("\"bounce_tolerance\": 2"),
              {"pointcloud.bounce_tolerance", "outside"});
  // Anderson mixing of the passes: "auto" by default (the passes choose), or 0-16 past
  // passes.
  EXPECT_EQ(minimal.pointcloud.bounceMixingDepth, kAutoBounceMixing);
  EXPECT_EQ(parseScene(withPointCloud("\"bounce_mixing_depth\": \"auto\""), "/tmp/scene.json")
                .pointcloud.bounceMixingDepth,
            kAutoBounceMixing);
  EXPECT_EQ(parseScene(withPointCloud("\"bounce_mixing_depth\": 3"), "/tmp/scene.json")
                .pointcloud.bounceMixingDepth,
            3);
  EXPECT_EQ(parseScene(withPointCloud("\"bounce_mixing_depth\": 0"), "/tmp/scene.json")
                .pointcloud.bounceMixingDepth,
            0);
  expectError(withPointCloud("\"bounce_mixing_depth\": 17"),
              {"pointcloud.bounce_mixing_depth", "outside"});
  expectError(withPointCloud("\"bounce_mixing_depth\": -1"),
              {"pointcloud.bounce_mixing_depth", "outside"});
  expectError(withPointCloud("\"bounce_mixing_depth\": \"fast\""),
              {"pointcloud.bounce_mixing_depth", "a depth or \"auto\"", "fast"});
  expectError(withPointCloud("\"bounce_mixing_depth\": true"),
              {"pointcloud.bounce_mixing_depth", "a depth or \"auto\", got boolean"});
}

// Lvoxel clusters default by visibility: ray-traced gathers march every lvoxel (faster
// than the clusters were), disk visibility keeps them; a given value holds for both.
TEST(SceneLoader, LvoxelClustersDefaultByVisibility) {
  auto angle = [](const std::string& settings) {
    const std::string text =
        withField("\"lights\"", "\"pointcloud\": {" + settings + "}, \"lights\"");
    return parseScene(text, "/tmp/scene.json").pointcloud.lvoxelClusterSolidAngle;
  };
  EXPECT_EQ(parseScene(kMinimal, "/tmp/scene.json").pointcloud.lvoxelClusterSolidAngle, 0.0f);
  EXPECT_EQ(angle(""), 0.0f);
  EXPECT_EQ(angle("\"gather_visibility\": \"rays\""), 0.0f);
  EXPECT_EQ(angle("\"gather_visibility\": \"cloud\""), 0.03f);
  EXPECT_EQ(angle("\"gather_visibility\": \"cloud\", \"lvoxel_cluster_solid_angle\": 0"), 0.0f);
  EXPECT_EQ(angle("\"lvoxel_cluster_solid_angle\": 0.05"), 0.05f);
}

TEST(SceneLoader, UnknownKeysAreErrors) {
  expectError(withField("\"vfov_deg\"", "\"vfov\": 3, \"vfov_deg\""), {"camera.vfov", "unknown"});
  expectError(withField("\"camera\"", "\"camrea\": {}, \"camera\""), {"camrea", "unknown"});
  expectError(withField("\"type\": \"directional\"", "\"type\": \"sun\""), {"lights[0].type"});
  expectError(withField("\"material\": \"white\"", "\"material\": \"black\""),
              {"shapes[0].material", "black"});
}

TEST(SceneLoader, TransformsScaleRotateTranslate) {
  const std::string text = withField(
      "\"material\": \"white\"}",
      "\"material\": \"white\", \"transform\": {\"scale\": 2, \"rotate\": {\"axis\": [0,1,0], "
      "\"deg\": 90}, \"translate\": [10, 0, 0]}}");
  const Scene scene = parseScene(text, "/tmp/scene.json");
  // Corner (-1,0,-1): scaled to (-2,0,-2), rotated 90 deg about y to (-2,0,2), moved by +10 x.
  const Vec3 p = scene.world.mesh.vertex(0, 0);
  EXPECT_NEAR(p.x, 8.0f, 1e-5f);
  EXPECT_NEAR(p.y, 0.0f, 1e-5f);
  EXPECT_NEAR(p.z, 2.0f, 1e-5f);
}

TEST(SceneLoader, ObjWithMtlColours) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "m.mtl", "newmtl red\nKd 0.8 0.1 0.1\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n");
  test::writeFile(dir / "m.obj",
                  "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 0\n"
                  "usemtl red\nf 1 2 3 4\nusemtl lamp\nf 1 2 3\n"
                  "f 1 2 5\n");  // the last face is degenerate: skipped
  test::writeFile(dir / "s.json",
                  std::string(R"({"camera": {"position": [0,0,5], "look_at": [0,0,0]},
    "shapes": [{"type": "obj", "file": "m.obj"}]})"));
  const Scene scene = loadScene((dir / "s.json").string());
  ASSERT_EQ(scene.world.mesh.triangleCount(), 3u);  // quad -> 2 triangles, plus one
  const Material& red = scene.world.materials[scene.world.mesh.triangleMaterial[0]];
  EXPECT_FLOAT_EQ(red.albedo.x, 0.8f);
  EXPECT_FLOAT_EQ(red.albedo.y, 0.1f);
  const Material& lamp = scene.world.materials[scene.world.mesh.triangleMaterial[2]];
  EXPECT_TRUE(lamp.isEmissive());
  EXPECT_FLOAT_EQ(lamp.emission.x, 5.0f);
}

TEST(SceneLoader, MtlEmissionBeyondTheSceneFilesBoundIsRefused) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "m.mtl", "newmtl sun\nKd 0 0 0\nKe 1e20 1e20 1e20\n");
  test::writeFile(dir / "m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl sun\nf 1 2 3\n");
  test::writeFile(dir / "s.json", R"({"camera": {"position": [0,0,5], "look_at": [0,0,0]},
    "shapes": [{"type": "obj", "file": "m.obj"}]})");
  try {
    loadScene((dir / "s.json").string());
    FAIL() << "Ke 1e20 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("material 'sun': Ke outside"), std::string::npos)
        << e.what();
  }
}

// Silently accepted before: a key given twice (the last one won) and a zero up vector.
TEST(SceneLoader, DuplicateKeysAndAZeroUpVectorAreRefused) {
  expectError(withField("\"vfov_deg\": 40", "\"vfov_deg\": 40, \"vfov_deg\": 60"),
              {"camera.vfov_deg", "given twice"});
  expectError(withField("\"camera\"", "\"render\": {\"spp\": 2}, \"render\": {}, \"camera\""),
              {"render", "given twice"});
  expectError(withField("\"look_at\": [0, 0, 0]", "\"look_at\": [0, 0, 0], \"up\": [0, 0, 0]"),
              {"camera.up", "must not be zero"});
}

TEST(SceneLoader, ObjBadIndexAndMissingFile) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "bad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 7\n");
  test::writeFile(dir / "s.json", R"({"camera": {"position": [0,0,5], "look_at": [0,0,0]},
    "shapes": [{"type": "obj", "file": "bad.obj"}]})");
  try {
    loadScene((dir / "s.json").string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.obj"), std::string::npos) << e.what();
  }
  test::writeFile(dir / "s2.json", R"({"camera": {"position": [0,0,5], "look_at": [0,0,0]},
    "shapes": [{"type": "obj", "file": "missing.obj"}]})");
  try {
    loadScene((dir / "s2.json").string());
    FAIL();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("missing.obj"), std::string::npos) << msg;
    EXPECT_NE(msg.find("shapes[0].file"), std::string::npos) << msg;
  }
}

TEST(SceneLoader, PlyAsciiAndBinary) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "a.ply",
                  "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                  "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                  "end_header\n0 0 0\n2 0 0\n2 2 0\n0 2 0\n4 0 1 2 3\n");
  test::writeFile(dir / "s.json", R"({"camera": {"position": [0,0,5], "look_at": [0,0,0]},
    "materials": {"m": {"albedo": 0.5}},
    "shapes": [{"type": "ply", "file": "a.ply", "material": "m", "transform": {"translate": [0,0,3]}}]})");
  const Scene scene = loadScene((dir / "s.json").string());
  ASSERT_EQ(scene.world.mesh.triangleCount(), 2u);
  const Bounds3 b = scene.world.bounds();
  EXPECT_FLOAT_EQ(b.hi.x, 2.0f);
  EXPECT_FLOAT_EQ(b.lo.z, 3.0f);
  test::writeFile(dir / "c.ply", "ply\nformat ascii 1.0\nelement vertex 4\nthis is garbage\n");
  test::writeFile(dir / "s2.json", R"({"camera": {"position": [0,0,5], "look_at": [0,0,0]},
    "materials": {"m": {"albedo": 0.5}}, "shapes": [{"type": "ply", "file": "c.ply", "material": "m"}]})");
  EXPECT_THROW(loadScene((dir / "s2.json").string()), InputError);
}

TEST(SceneLoader, RealBunnyPly) {
  const std::string path = std::string(LVOX_SHARED_DIR) + "/assets/bunny/bun_zipper_res2.ply";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared assets absent: " << path;
  const auto dir = test::tempDir();
  test::writeFile(dir / "s.json", R"({"camera": {"position": [0,0,5], "look_at": [0,0,0]},
    "materials": {"m": {"albedo": 0.5}}, "shapes": [{"type": "ply", "file": ")" +
                                      path + R"(", "material": "m"}]})");
  const Scene scene = loadScene((dir / "s.json").string());
  // The decimated Stanford bunny has 16,301 triangles (shared/assets/README.md).
  EXPECT_NEAR(static_cast<double>(scene.world.mesh.triangleCount()), 16301.0, 5.0);
}

}  // namespace
}  // namespace lvox

namespace lvox {
namespace {

// Truncated and corrupted copies of a valid binary-free PLY must give an error or a
// smaller mesh, never a hang or a crash.
TEST(SceneLoader, PlyTruncatedAndCorrupt) {
  const auto dir = test::tempDir();
  const std::string good =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
      "end_header\n0 0 0\n2 0 0\n2 2 0\n0 2 0\n3 0 1 2\n3 0 2 3\n";
  test::writeFile(dir / "s.json", R"({"camera": {"position": [0,0,5], "look_at": [0,0,0]},
    "materials": {"m": {"albedo": 0.5}}, "shapes": [{"type": "ply", "file": "x.ply", "material": "m"}]})");
  for (size_t cut : {good.size() / 4, good.size() / 2, good.size() - 8}) {
    test::writeFile(dir / "x.ply", good.substr(0, cut));
    try {
      const Scene scene = loadScene((dir / "s.json").string());
      EXPECT_LE(scene.world.mesh.triangleCount(), 2u);
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("x.ply"), std::string::npos) << e.what();
    }
  }
  std::string outOfRange = good;
  outOfRange.replace(outOfRange.find("3 0 2 3"), 7, "3 0 2 9");
  test::writeFile(dir / "x.ply", outOfRange);
  try {
    const Scene scene = loadScene((dir / "s.json").string());
    EXPECT_LE(scene.world.mesh.triangleCount(), 1u);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("x.ply"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace lvox
