// Blackbody emission: Planck's law, its colour, the table the hot path reads, and media
// with a temperature grid (Blender's smoke and fire caches).
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <cmath>

#include "src/core/json_fields.h"
#include "test_util.h"
#include "volume/media/blackbody.h"
#include "volume/media/media_set.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

TEST(Blackbody, PlanckIntegratesToStefanBoltzmann) {
  for (double kelvin : {800.0, 1500.0, 6000.0}) {
    // Log-spaced midpoint rule from 10 nm to 1 mm.
    double sum = 0.0;
    const double lo = std::log(10e-9), hi = std::log(1e-3);
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      const double u = lo + (hi - lo) * (i + 0.5) / n;
      const double lambda = std::exp(u);
      sum += planck(lambda, kelvin) * lambda * (hi - lo) / n;
    }
    const double expected = kStefanBoltzmann * std::pow(kelvin, 4.0) / kPi;
    EXPECT_NEAR(sum / expected, 1.0, 1e-4) << kelvin;
  }
}

TEST(Blackbody, ColourLiesOnThePlanckianLocus) {
  // CIE 1931 xy of the Planckian locus (Wyszecki & Stiles); the colour matching functions are
  // a fit within about 1 %, hence 0.004.
  const struct {
    double kelvin, x, y;
  } locus[] = {{2000.0, 0.5267, 0.4133}, {4000.0, 0.3805, 0.3768}, {6500.0, 0.3135, 0.3237}};
  for (const auto& p : locus) {
    const Vec3 xyz = blackbodyXyz(p.kelvin);
    const double s = static_cast<double>(xyz.x) + xyz.y + xyz.z;
    EXPECT_NEAR(xyz.x / s, p.x, 0.004) << p.kelvin;
    EXPECT_NEAR(xyz.y / s, p.y, 0.004) << p.kelvin;
  }
}

TEST(Blackbody, RadianceHasTheStefanBoltzmannLuminance) {
  // Inside the sRGB gamut (no clamped channel) the Rec.709 luminance of rgb(T) is
  // sigma T^4 / pi; fire is red, hot stars blue.
  for (double kelvin : {3000.0, 5000.0, 9000.0}) {
    const RGB c = blackbodyRadiance(kelvin);
    const double luminance = 0.2126729 * c.x + 0.7151522 * c.y + 0.0721750 * c.z;
    EXPECT_NEAR(luminance / (kStefanBoltzmann * std::pow(kelvin, 4.0) / kPi), 1.0, 1e-4);
  }
  const RGB fire = blackbodyChromaticity(1500.0), star = blackbodyChromaticity(12000.0);
  EXPECT_GT(fire.x, 4.0f * fire.z);
  EXPECT_GT(star.z, star.x);
  EXPECT_EQ(blackbodyRadiance(0.0), RGB(0.0f));
}

TEST(Blackbody, TheTableMatchesTheDirectValues) {
  const BlackbodyTable table(3000.0f);
  for (float kelvin = 700.0f; kelvin < 3000.0f; kelvin += 123.4f) {
    const RGB a = table(kelvin), b = blackbodyRadiance(kelvin);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 2e-3f * b[c] + 1e-6f) << kelvin;
  }
  EXPECT_EQ(table(5000.0f), table(3000.0f));  // clamped to the grid's hottest voxel
}

// A VDB with a constant cube of density and temperature (as Blender writes them, the
// temperature normalised to [0, 1]) and a vector grid.
fs::path writeFire(const fs::path& dir) {
  openvdb::initialize();
  auto density = openvdb::FloatGrid::create(0.0f);
  density->setName("density");
  auto temperature = openvdb::FloatGrid::create(0.0f);
  temperature->setName("temperature");
  auto velocity = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  velocity->setName("velocity");
  const openvdb::CoordBBox box(openvdb::Coord(0), openvdb::Coord(15));
  density->tree().fill(box, 0.5f, true);
  temperature->tree().fill(box, 0.75f, true);
  velocity->tree().fill(box, openvdb::Vec3s(0.0f, 1.0f, 0.0f), true);
  const fs::path path = dir / "fire.vdb";
  openvdb::io::File(path.string()).write({density, temperature, velocity});
  return path;
}

MediaSet fireMedia(const fs::path& dir, const std::string& extra,
                   std::vector<std::string>& warnings) {
  writeFire(dir);
  const nlohmann::json json = nlohmann::json::parse(
      R"({"type": "vdb", "file": "fire.vdb", "density_scale": 2, "albedo": 0.25)" + extra + "}");
  std::vector<MediumDesc> descs{
      parseMedium(JsonObject(json, (dir / "s.json").string(), "media[0]"))};
  return MediaSet::build(descs, Interpolation::Trilinear, warnings);
}

TEST(Blackbody, ATemperatureGridEmitsSigmaATimesPlanck) {
  const fs::path dir = test::tempDir();
  std::vector<std::string> warnings;
  const MediaSet media = fireMedia(
      dir,
      R"(, "temperature_grid": "temperature", "temperature": 2000, "blackbody_intensity": 0.5)",
      warnings);
  // sigma_t = 2 x 0.5 = 1, sigma_a = 0.75; T = 2000 x 0.75 = 1500 K.
  const MediumCoefficients c = media.at(Vec3(8.0f, 8.0f, 8.0f));
  const RGB expected = blackbodyRadiance(1500.0) * (0.75f * 0.5f);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(c.source[k], expected[k], 2e-3f * expected[k] + 1e-3f);
  EXPECT_GT(c.source.x, 1000.0f);  // sigma (1500 K)^4 / pi = 9.1e4 W m^-2 sr^-1
  // The unused vector grid is named, with why.
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("'velocity' (not used: vec3s grids"), std::string::npos)
      << warnings[0];
}

TEST(Blackbody, UnusedBlenderGridsAreNamedWithWhatTheyCouldMean) {
  const fs::path dir = test::tempDir();
  std::vector<std::string> warnings;
  const MediaSet media = fireMedia(dir, "", warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("'temperature' (not used; as \"temperature_grid\""), std::string::npos)
      << warnings[0];
  EXPECT_EQ(media.at(Vec3(8.0f, 8.0f, 8.0f)).source, RGB(0.0f));
}

}  // namespace
}  // namespace lvox
