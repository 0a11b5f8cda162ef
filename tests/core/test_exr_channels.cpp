// Every channel of an EXR: layers survive a round trip in display order, and the colour
// of a layered file is what readExr gives.
#include <gtest/gtest.h>

#include "src/core/error.h"
#include "src/core/exr_channels.h"
#include "test_util.h"

namespace lvox {
namespace {

TEST(ExrChannels, RoundTripKeepsEveryLayerInDisplayOrder) {
  const auto dir = test::tempDir();
  ExrChannels c;
  c.width = 3;
  c.height = 2;
  c.names = {"depth.Z", "B", "albedo.G", "G", "albedo.R", "R", "albedo.B", "A"};
  for (size_t i = 0; i < c.names.size(); ++i)
    c.planes.push_back(std::vector<float>(6, static_cast<float>(i) + 0.5f));
  c.planes[5][4] = 7.25f;  // R at pixel (1, 1)
  c.metadata["lvox.mode"] = "pcb";
  writeExrChannels((dir / "a.exr").string(), c);
  const ExrChannels r = readExrChannels((dir / "a.exr").string());
  EXPECT_EQ(r.names, (std::vector<std::string>{"R", "G", "B", "A", "albedo.R", "albedo.G",
                                               "albedo.B", "depth.Z"}));
  EXPECT_EQ(r.width, 3);
  EXPECT_EQ(r.height, 2);
  EXPECT_EQ(r.metadata.at("lvox.mode"), "pcb");
  EXPECT_FLOAT_EQ((*r.find("depth.Z"))[0], 0.5f);
  EXPECT_FLOAT_EQ((*r.find("albedo.B"))[3], 6.5f);
  EXPECT_EQ(r.find("Y"), nullptr);
  const std::optional<Image> colour = colourImage(r);
  ASSERT_TRUE(colour);
  EXPECT_FLOAT_EQ(colour->at(1, 1)[0], 7.25f);
  EXPECT_FLOAT_EQ(colour->at(1, 1)[2], 1.5f);
  const Image same = readExr((dir / "a.exr").string());
  EXPECT_EQ(same.pixels, colour->pixels);
}

TEST(ExrChannels, LayersAndBadFiles) {
  EXPECT_EQ(channelLayer("R"), "");
  EXPECT_EQ(channelLayer("diffuse.albedo.R"), "diffuse.albedo");
  const auto dir = test::tempDir();
  test::writeFile(dir / "bad.exr", "not an exr");
  EXPECT_THROW(readExrChannels((dir / "bad.exr").string()), InputError);
  EXPECT_THROW(readExrChannels((dir / "none.exr").string()), InputError);
  ExrChannels grey;
  grey.width = grey.height = 1;
  grey.names = {"depth.Z"};
  grey.planes = {{1.0f}};
  EXPECT_FALSE(colourImage(grey));
}

}  // namespace
}  // namespace lvox
