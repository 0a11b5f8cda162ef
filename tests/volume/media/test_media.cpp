#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <cmath>
#include <fstream>

#include "src/core/error.h"
#include "src/core/json_fields.h"
#include "src/core/rng.h"
#include "test_util.h"
#include "volume/media/media_set.h"
#include "volume/media/medium_desc.h"
#include "volume/phase.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

// Writes a VDB with one float grid filled by f(i, j, k) over [0, n)^3, voxel size `voxel`.
template <class F>
void writeGrid(const fs::path& path, int n, double voxel, F f, const std::string& name = "density",
               bool levelSet = false) {
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName(name);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
  if (levelSet) grid->setGridClass(openvdb::GRID_LEVEL_SET);
  auto acc = grid->getAccessor();
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const float v = f(i, j, k);
        if (v != 0.0f) acc.setValue(openvdb::Coord(i, j, k), v);
      }
  openvdb::io::File(path.string()).write({grid});
}

// A scene file's "media" array, parsed by the volume library as the scene loader does
// (relative file names resolve against `dir`).
std::vector<MediumDesc> parseMediaArray(const fs::path& dir, const std::string& text) {
  const nlohmann::json array = nlohmann::json::parse(text);
  std::vector<MediumDesc> out;
  for (size_t i = 0; i < array.size(); ++i)
    out.push_back(parseMedium(
        JsonObject(array[i], (dir / "s.json").string(), "media[" + std::to_string(i) + "]")));
  return out;
}

std::vector<MediumDesc> vdbMedium(const fs::path& dir, const std::string& file,
                                  const std::string& extra = "") {
  return parseMediaArray(
      dir, R"([{"type": "vdb", "file": ")" + file + R"(", "density_scale": 2)" + extra + "}]");
}

MediaSet build(const std::vector<MediumDesc>& media, std::vector<std::string>& warnings,
               Interpolation interpolation = Interpolation::Trilinear) {
  return MediaSet::build(media, interpolation, warnings);
}

std::string buildError(const std::vector<MediumDesc>& media) {
  std::vector<std::string> warnings;
  try {
    build(media, warnings);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Media, TrilinearReproducesALinearFieldExactly) {
  const auto dir = test::tempDir();
  writeGrid(dir / "ramp.vdb", 16, 0.5, [](int i, int j, int k) {
    return 1.0f + 0.5f * static_cast<float>(i) + 0.25f * static_cast<float>(j) +
           0.125f * static_cast<float>(k);
  });
  const auto descs = vdbMedium(dir, "ramp.vdb", R"(, "transform": {"translate": [1, 2, 3]})");
  std::vector<std::string> warnings;
  const MediaSet media = build(descs, warnings);
  ASSERT_EQ(media.size(), 1u);
  // World p -> index (p - translate) / 0.5; sigma_t = 2 * density.
  for (const Vec3& p : {Vec3(2.3f, 3.7f, 5.1f), Vec3(4.9f, 6.1f, 3.3f), Vec3(1.25f, 2.75f, 6.6f)}) {
    const Vec3 idx = (p - Vec3(1, 2, 3)) / 0.5f;
    const float expected = 2.0f * (1.0f + 0.5f * idx.x + 0.25f * idx.y + 0.125f * idx.z);
    EXPECT_NEAR(media.at(p).sigmaT().x, expected, 1e-4f * expected);
  }
}

TEST(Media, RotatedGridAndNearestLookup) {
  const auto dir = test::tempDir();
  writeGrid(dir / "g.vdb", 8, 1.0, [](int i, int, int) { return static_cast<float>(i + 1); });
  std::vector<std::string> warnings;
  const MediaSet media = build(parseMediaArray(dir, R"([{"type": "vdb", "file": "g.vdb",
    "transform": {"rotate": {"axis": [0,0,1], "deg": 90}}}])"),
                               warnings, Interpolation::Nearest);
  // Rotating 90 deg about z maps index x to world y: voxel i=3 (density 4) is at world y=3.
  EXPECT_FLOAT_EQ(media.at(Vec3(-2.0f, 3.1f, 2.0f)).sigmaT().x, 4.0f);
  EXPECT_FLOAT_EQ(media.at(Vec3(-2.0f, 5.4f, 2.0f)).sigmaT().x, 6.0f);  // voxel centres at integers
}

TEST(Media, IntervalsSkipEmptySpaceBetweenBlobs) {
  const auto dir = test::tempDir();
  // Two 4^3 blobs at i in [0,4) and [40,44), far apart along x.
  writeGrid(dir / "two.vdb", 48, 1.0, [](int i, int j, int k) {
    const bool inY = j >= 20 && j < 24 && k >= 20 && k < 24;
    return inY && (i < 4 || (i >= 40 && i < 44)) ? 1.0f : 0.0f;
  });
  std::vector<std::string> warnings;
  const MediaSet media = build(vdbMedium(dir, "two.vdb"), warnings);
  Ray ray;
  ray.origin = Vec3(-10.0f, 21.5f, 21.5f);
  ray.dir = Vec3(1, 0, 0);
  std::vector<std::pair<float, float>> spans;
  media.intervals(ray, 0.0f, 1e30f, spans);
  ASSERT_EQ(spans.size(), 2u);
  // Every active voxel is covered (x in [-0.5, 3.5] and [39.5, 43.5], t = x + 10)...
  EXPECT_LE(spans[0].first, 9.5f);
  EXPECT_GE(spans[0].second, 13.5f);
  EXPECT_LE(spans[1].first, 49.5f);
  EXPECT_GE(spans[1].second, 53.5f);
  // ... and the empty 36 voxels between them are skipped (up to the block padding).
  EXPECT_GT(spans[1].first - spans[0].second, 10.0f);
  // The optical depth over the intervals equals the sum over the 8 voxels (nearest).
}

TEST(Media, LoadErrorsNameFileAndField) {
  const auto dir = test::tempDir();
  EXPECT_NE(buildError(vdbMedium(dir, "missing.vdb")).find("missing.vdb"), std::string::npos);
  test::writeFile(dir / "junk.vdb", std::string(4096, 'x'));
  const std::string junk = buildError(vdbMedium(dir, "junk.vdb"));
  EXPECT_NE(junk.find("media[0].grid"), std::string::npos) << junk;
  EXPECT_NE(junk.find("not a readable OpenVDB"), std::string::npos) << junk;
  writeGrid(
      dir / "named.vdb", 4, 1.0, [](int, int, int) { return 1.0f; }, "smoke");
  const std::string wrong = buildError(vdbMedium(dir, "named.vdb"));
  EXPECT_NE(wrong.find("'smoke' (float)"), std::string::npos) << wrong;  // lists the grids
  writeGrid(
      dir / "ls.vdb", 4, 1.0, [](int, int, int) { return 1.0f; }, "density", true);
  EXPECT_NE(buildError(vdbMedium(dir, "ls.vdb")).find("level set"), std::string::npos);
}

TEST(Media, TruncatedAndCorruptRealVdb) {
  const std::string real = std::string(LVOX_SHARED_DIR) + "/assets/vdb/smoke.vdb";
  if (!fs::exists(real)) GTEST_SKIP() << "shared assets absent";
  const auto dir = test::tempDir();
  std::ifstream in(real, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (size_t k : {1u, 8u, 15u}) {
    test::writeFile(dir / "cut.vdb", bytes.substr(0, bytes.size() * k / 16));
    EXPECT_NE(buildError(vdbMedium(dir, "cut.vdb")), "") << k << "/16";
  }
}

TEST(Media, Vec3GridIsRejected) {
  const std::string plume = std::string(LVOX_SHARED_DIR) + "/assets/vdb/blender_smoke_plume.vdb";
  if (!fs::exists(plume)) GTEST_SKIP() << "shared assets absent";
  const auto dir = test::tempDir();
  const std::string msg = buildError(vdbMedium(dir, plume, R"(, "grid": "velocity")"));
  EXPECT_NE(msg.find("float grid"), std::string::npos) << msg;
  // The density grid of the same file loads.
  EXPECT_EQ(buildError(vdbMedium(dir, plume)), "");
}

// A finite density that overflows sigma_t (3e38 x 2) or merely exceeds the bound of every
// medium (1e9 per unit) is refused, naming the density scale; direct mode used to make
// pixels of 9e37 of it and mc never ended.
TEST(Media, DensityTimesScaleBeyondTheBoundIsRefused) {
  const auto dir = test::tempDir();
  writeGrid(dir / "huge.vdb", 4, 1.0, [](int, int, int) { return 3e38f; });
  const std::string msg = buildError(vdbMedium(dir, "huge.vdb"));  // density_scale 2
  EXPECT_NE(msg.find("media[0].density_scale"), std::string::npos) << msg;
  EXPECT_NE(msg.find("exceeds sigma_t = 1e9"), std::string::npos) << msg;
  writeGrid(dir / "fine.vdb", 4, 1.0, [](int, int, int) { return 4e8f; });
  EXPECT_EQ(buildError(vdbMedium(dir, "fine.vdb")), "");  // 8e8: within the bound
}

TEST(Media, NegativeVoxelsAreClampedAndNaNIsAnError) {
  const auto dir = test::tempDir();
  writeGrid(dir / "neg.vdb", 4, 1.0, [](int i, int, int) { return i == 0 ? -1.0f : 1.0f; });
  std::vector<std::string> warnings;
  const MediaSet media = build(vdbMedium(dir, "neg.vdb"), warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("16 negative voxels"), std::string::npos) << warnings[0];
  EXPECT_GE(media.at(Vec3(0.0f, 1.0f, 1.0f)).sigmaT().x, 0.0f);
  writeGrid(dir / "nan.vdb", 4, 1.0, [](int i, int, int) { return i == 1 ? NAN : 1.0f; });
  EXPECT_NE(buildError(vdbMedium(dir, "nan.vdb")).find("NaN"), std::string::npos);
}

// A grid with no active voxel (an empty tree) passes the file walk and loads as an empty
// medium, with a warning naming it: nothing to render, nothing refused.
TEST(Media, AnEmptyGridIsAnEmptyMediumWithAWarning) {
  const auto dir = test::tempDir();
  writeGrid(dir / "empty.vdb", 4, 1.0, [](int, int, int) { return 0.0f; });
  std::vector<std::string> warnings;
  const MediaSet media = build(vdbMedium(dir, "empty.vdb"), warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("has no active voxels: empty medium"), std::string::npos)
      << warnings[0];
  EXPECT_EQ(media.at(Vec3(1.0f, 1.0f, 1.0f)).sigmaT().x, 0.0f);
}

TEST(Media, OverlappingBoxesAdd) {
  std::vector<std::string> warnings;
  const MediaSet media = build(parseMediaArray("/tmp", R"([
    {"type": "homogeneous", "min": [0,0,0], "max": [2,2,2], "sigma_a": 0.5, "sigma_s": 1},
    {"type": "homogeneous", "min": [1,1,1], "max": [3,3,3], "sigma_a": 0.25, "sigma_s": 0}])"),
                               warnings);
  EXPECT_FLOAT_EQ(media.at(Vec3(1.5f)).sigmaT().x, 1.75f);
  EXPECT_FLOAT_EQ(media.at(Vec3(0.5f)).sigmaT().x, 1.5f);
  EXPECT_FLOAT_EQ(media.at(Vec3(2.5f)).sigmaA.x, 0.25f);
  Ray ray;
  ray.origin = Vec3(-1, 1.5f, 1.5f);
  ray.dir = Vec3(1, 0, 0);
  std::vector<std::pair<float, float>> spans;
  media.intervals(ray, 0, 100, spans);
  ASSERT_EQ(spans.size(), 1u);  // merged
  EXPECT_FLOAT_EQ(spans[0].first, 1.0f);
  EXPECT_FLOAT_EQ(spans[0].second, 4.0f);
}

// Integrates p over the sphere with a fine midpoint rule in cos(theta).
double sphereIntegral(const PhaseFunction& p, int power) {
  const int n = 200000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double mu = -1.0 + (i + 0.5) * 2.0 / n;
    sum += p.eval(static_cast<float>(mu)) * std::pow(mu, power);
  }
  return sum * 2.0 / n * 2.0 * M_PI;
}

TEST(Phase, NormalisedWithTheRightMeanCosine) {
  for (float g : {-0.7f, -0.2f, 0.3f, 0.8f}) {
    const PhaseFunction hg = PhaseFunction::make(PhaseKind::HenyeyGreenstein, g);
    EXPECT_NEAR(sphereIntegral(hg, 0), 1.0, 1e-4) << g;
    EXPECT_NEAR(sphereIntegral(hg, 1), g, 1e-3) << g;
    const PhaseFunction schlick = PhaseFunction::make(PhaseKind::Schlick, g);
    EXPECT_NEAR(sphereIntegral(schlick, 0), 1.0, 1e-4) << g;
    // Schlick's k = 1.55 g - 0.55 g^3 fit is approximate: measured mean cosines are
    // 0.873 for g = 0.8 and -0.760 for g = -0.7 (about 9 % strong), hence 0.08.
    EXPECT_NEAR(sphereIntegral(schlick, 1), g, 0.08) << g;
  }
  EXPECT_NEAR(sphereIntegral(PhaseFunction::make(PhaseKind::Isotropic, 0.0f), 0), 1.0, 1e-6);
}

TEST(Phase, SamplingFollowsTheFunction) {
  for (const PhaseKind kind : {PhaseKind::HenyeyGreenstein, PhaseKind::Schlick}) {
    const PhaseFunction p = PhaseFunction::make(kind, 0.6f);
    Rng rng(3, 4);
    const Vec3 wIn = normalize(Vec3(0.3f, -0.5f, 0.8f));
    double meanCos = 0.0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      float pdf;
      const Vec3 w = p.sample(wIn, rng.uniform(), rng.uniform(), pdf);
      const float c = dot(w, wIn);
      ASSERT_NEAR(pdf, p.eval(c), 1e-3f * pdf + 1e-6f);
      meanCos += c;
    }
    // The sample mean of cos matches the integral (std error ~ 0.5/sqrt(n) = 1e-3).
    EXPECT_NEAR(meanCos / n, sphereIntegral(p, 1), 5e-3) << static_cast<int>(kind);
  }
}

}  // namespace
}  // namespace lvox
