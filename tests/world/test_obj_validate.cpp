// The OBJ check of src/world/obj_validate.h: `vw` joint ids that tinyobjloader would convert
// to int with undefined behaviour (found by fuzzing) are refused, naming the line; valid
// skin weights and every other line are left to tinyobjloader.
#include <gtest/gtest.h>

#include "src/core/error.h"
#include "src/world/mesh_loader.h"
#include "src/world/obj_validate.h"
#include "src/world/world.h"
#include "test_util.h"

namespace lvox {
namespace {

const std::string kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

std::string error(const std::string& text) {
  try {
    validateObjBytes(text, "a.obj", "shapes[0].file");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ObjValidate, JointIdsBeyondIntAreRefused) {
  // The fuzzer's input: an exponent that overflows to infinity, glued to more text.
  EXPECT_NE(error(kTriangle + "vw 2 1 0.5\nvw 2 2 0   21e3820p_d\n")
                .find("line 6: skin weight joint id '21e3820p_d' is not an int"),
            std::string::npos);
  EXPECT_NE(error(kTriangle + "vw 0 1e10 0.5\n").find("'1e10'"), std::string::npos);
  EXPECT_NE(error(kTriangle + "vw 0 2147483648 1\n"), "");  // 2^31
  // 0 x 10^500 is 0 * inf in tinyobjloader's arithmetic: NaN.
  EXPECT_NE(error(kTriangle + "vw 0 0e500 1\n"), "");
  // In the second pair, after \r\n line ends, with leading blanks.
  EXPECT_NE(error("v 0 0 0\r\n \tvw 0 1 0.5 3e9 0.5\r\n").find("line 2"), std::string::npos);
}

TEST(ObjValidate, ValidSkinWeightsAndOtherLinesPass) {
  EXPECT_EQ(error(kTriangle + "vw 0 0 0.25 1 0.25 2 0.5\n"), "");
  EXPECT_EQ(error(kTriangle + "vw 0 2147483520 1\n"), "");  // the largest float below 2^31
  EXPECT_EQ(error(kTriangle + "vw 0 -5 1\n"), "");          // negative: tinyobjloader refuses it
  EXPECT_EQ(error(kTriangle + "vw 0 inf 1\n"), "");         // not a number to it: -1, refused
  EXPECT_EQ(error("# vw 0 1e10 1\nvt 1e10 0\nv 1e40 0 0\n"), "");  // not `vw` lines
  EXPECT_EQ(error("vw\nvw 0\n"), "");
}

TEST(ObjValidate, LoadObjRefusesTheFileBeforeTinyObjLoaderReadsIt) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "w.obj", kTriangle + "vw 0 1e12 1\n");
  World world;
  try {
    loadObj((dir / "w.obj").string(), "shapes[0].file", Transform{}, std::nullopt, world);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("w.obj"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("line 5"), std::string::npos) << e.what();
  }
  test::writeFile(dir / "ok.obj", kTriangle + "vw 0 1 1\n");
  const MeshLoadStats stats =
      loadObj((dir / "ok.obj").string(), "shapes[0].file", Transform{}, std::nullopt, world);
  EXPECT_EQ(stats.triangles, 1u);
}

}  // namespace
}  // namespace lvox
