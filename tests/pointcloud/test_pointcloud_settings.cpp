// The point cloud's settings that are resolved only once the cloud is built.
#include <gtest/gtest.h>

#include "pointcloud/pointcloud_settings.h"

namespace lvox {
namespace {

// "gather_samples": "auto": the interreflection's gather rays over the final gathers'
// points, rounded up to a multiple of 16, within [64, 512]; a count given is kept.
TEST(PointCloudSettings, AutoFinalGatherRaysMatchTheCloudsGatherRays) {
  PointCloudSettings automatic;
  ASSERT_EQ(automatic.gatherSamples, kAutoGatherSamples);
  // The atrium at 512 x 512 (66,049 grid points, 737,736 cloud rays): 12 a point, so 64.
  EXPECT_EQ(finalGatherSamples(automatic, 737'736, 66'049), 64);
  // The closed room at 160 x 120 (4,941 points, 1,674,208 rays): 338.8, so 352.
  EXPECT_EQ(finalGatherSamples(automatic, 1'674'208, 4'941), 352);
  // The open town (9,417 points, 1,382,656 rays): 146.8, so 160.
  EXPECT_EQ(finalGatherSamples(automatic, 1'382'656, 9'417), 160);
  // The lamp hall (3,185 points, 1,679,496 rays): 527.3, so the most, 512.
  EXPECT_EQ(finalGatherSamples(automatic, 1'679'496, 3'185), 512);
  // A multiple of 16 stays; one ray more goes to the next.
  EXPECT_EQ(finalGatherSamples(automatic, 100 * 208, 100), 208);
  EXPECT_EQ(finalGatherSamples(automatic, 100 * 208 + 1, 100), 224);
  // No interreflection (bounces 0), or no points: the least.
  EXPECT_EQ(finalGatherSamples(automatic, 0, 4'941), 64);
  EXPECT_EQ(finalGatherSamples(automatic, 1'000'000, 0), 512);
  // Counts past 32 bits do not wrap.
  EXPECT_EQ(finalGatherSamples(automatic, 1ull << 40, 1), 512);
  EXPECT_EQ(gatherLightSamplesBase(automatic), 64);

  PointCloudSettings fixed;
  fixed.gatherSamples = 96;
  EXPECT_EQ(finalGatherSamples(fixed, 1'674'208, 4'941), 96);
  EXPECT_EQ(finalGatherSamples(fixed, 0, 1), 96);
  EXPECT_EQ(gatherLightSamplesBase(fixed), 96);
}

// What a render's header records: "auto", or the count given.
TEST(PointCloudSettings, TheHeaderRecordsAutoOrTheCount) {
  auto described = [](const PointCloudSettings& s) {
    const SettingList list = describe(s);  // items() refers into it
    for (const auto& [field, value] : list.items())
      if (field == "pointcloud.gather_samples") return value;
    return std::string("(absent)");
  };
  PointCloudSettings s;
  EXPECT_EQ(described(s), "auto");
  s.gatherSamples = 128;
  EXPECT_EQ(described(s), "128");
}

}  // namespace
}  // namespace lvox
