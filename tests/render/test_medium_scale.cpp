// Steps relative to the medium (src/render/medium_scale.h): each medium's own step, the
// scene's step settings applied to a segment, and a scene that renders the same in any units.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "render/scene_media.h"
#include "src/render/medium_scale.h"
#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"

namespace lvox {
namespace {

using Scales = test::SceneMedia;

constexpr const char* kCamera = R"("camera": {"position": [0, 0.5, -20], "look_at": [0, 0.5, 0]})";

TEST(MediumScales, AHeterogeneousMediumStepsOverItsNarrowestBump) {
  const Scales s(std::string("{") + kCamera + R"(,
    "media": [{"type": "procedural", "kind": "noise", "frequency": 4, "min": [-1, -1, -1],
               "max": [5, 2, 1], "sigma_a": 0.3, "sigma_s": 2},
              {"type": "procedural", "kind": "gaussian_blob", "center": [0, 0, 0], "radius": 0.3, "min": [-1, -1, -1],
               "max": [1, 1, 1], "sigma_a": 40, "sigma_s": 2}]})");
  EXPECT_FLOAT_EQ(s.scales->featureSize(0), 0.125f);  // half a period
  EXPECT_FLOAT_EQ(s.scales->step(0), 0.125f / 1.2f);
  // The blob's radius sets its step, not its density: auto splits steps by optical depth.
  EXPECT_FLOAT_EQ(s.scales->step(1), 0.3f / 1.2f);
}

TEST(MediumScales, AHomogeneousMediumStepsByItsMeanFreePathItsBoxAndTheShadowsInIt) {
  // No surfaces: 0.6 optical depths, or a sixteenth of the box's diagonal.
  const std::string slab = R"("media": [
    {"type": "homogeneous", "min": [-50, 0, -50], "max": [50, 1, 50], "sigma_a": 0.25, "sigma_s": 0.5},
    {"type": "homogeneous", "min": [-50, 2, -50], "max": [50, 3, 50], "sigma_a": 0.005, "sigma_s": 0.005}])";
  const Scales fog(std::string("{") + kCamera + "," + slab + "}");
  const float boxDiagonal = std::sqrt(100.0f * 100.0f * 2.0f + 1.0f);
  EXPECT_FLOAT_EQ(fog.scales->step(0), 0.6f / 0.75f);
  EXPECT_FLOAT_EQ(fog.scales->step(1), boxDiagonal / 16.0f);
  EXPECT_FLOAT_EQ(fog.scales->shadowScale(0), boxDiagonal / 16.0f);
  // A floor 12 units square casts shadows at 1/128 of its diagonal.
  const Scales room(std::string("{") + kCamera + "," + slab + R"(,
    "materials": {"floor": {"albedo": 0.5}},
    "shapes": [{"type": "quad", "corners": [[-6,0,-6],[6,0,-6],[6,0,6],[-6,0,6]], "material": "floor"}]})");
  const float floorScale = std::sqrt(288.0f) / 128.0f;
  EXPECT_FLOAT_EQ(room.scales->step(0), floorScale);
  EXPECT_FLOAT_EQ(room.scales->shadowScale(1), floorScale);
  // A heterogeneous medium casts shadows at its own step.
  const Scales cloud(std::string("{") + kCamera + R"(,"media": [
    {"type": "homogeneous", "min": [-50, 0, -50], "max": [50, 1, 50], "sigma_a": 0.25, "sigma_s": 0.5},
    {"type": "procedural", "kind": "noise", "frequency": 2, "min": [-1, 2, -1], "max": [1, 3, 1],
     "sigma_a": 0.3, "sigma_s": 2}]})");
  EXPECT_FLOAT_EQ(cloud.scales->step(0), 0.25f / 1.2f);
}

TEST(MediumScales, ASegmentTakesTheSmallestStepOfTheMediaOnIt) {
  const Scales s(std::string("{") + kCamera + R"(,"media": [
    {"type": "homogeneous", "min": [-50, 0, -50], "max": [50, 1, 50], "sigma_a": 0.25, "sigma_s": 0.5},
    {"type": "procedural", "kind": "noise", "frequency": 4, "min": [10, 0, -1], "max": [12, 1, 1],
     "sigma_a": 0.3, "sigma_s": 2}]})");
  Ray ray;
  ray.origin = {-20, 0.5, 0};
  ray.dir = {1, 0, 0};
  // The noise medium's step needs a homogeneous one below its own (its shadows).
  EXPECT_FLOAT_EQ(s.scales->step(ray, 20.0f, 25.0f), 0.125f / 1.2f);
  EXPECT_FLOAT_EQ(s.scales->step(ray, 30.0f, 32.0f), 0.125f / 1.2f);
  EXPECT_FLOAT_EQ(s.scales->step(0), 0.125f / 1.2f);
  ray.origin = {-20, 5, 0};  // above both: no medium, one step
  EXPECT_EQ(s.scales->step(ray, 0.0f, 100.0f), 100.0f);
}

TEST(StepLengths, AbsoluteLengthsWinAndTheRestFollowTheStep) {
  rte::SolveSettings<float> s;
  StepLengths relative;
  relative.scale = 0.5f;
  relative.apply(2.0f, s);
  EXPECT_FLOAT_EQ(s.step, 1.0f);
  EXPECT_FLOAT_EQ(s.minStep, 2e-3f);
  EXPECT_FLOAT_EQ(s.maxStep, 20.0f);
  StepLengths absolute;
  absolute.step = 0.1f;
  absolute.apply(2.0f, s);
  EXPECT_FLOAT_EQ(s.step, 0.1f);
  EXPECT_FLOAT_EQ(s.minStep, 1e-4f);  // the old absolute defaults, for the old default step
  EXPECT_FLOAT_EQ(s.maxStep, 1.0f);
  absolute.minStep = 0.01f;
  absolute.maxStep = 0.2f;
  absolute.apply(2.0f, s);
  EXPECT_FLOAT_EQ(s.minStep, 0.01f);
  EXPECT_FLOAT_EQ(s.maxStep, 0.2f);
}

// One scene in two units: lengths x64, coefficients and frequencies / 64. A power of two
// scales every float exactly, so with steps relative to the medium every method takes the
// same steps in both and renders the same image to the bit; with one absolute step it does
// not. (At x100 rounding moves a node here and there, and the images differ by the
// discretisation error, 0.5 % here.)
constexpr float kUnit = 64.0f;

std::string number(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
  return buf;
}

std::string sceneIn(float unit, const std::string& integrator) {
  auto n = [unit](float v) { return number(v * unit); };
  auto per = [unit](float v) { return number(v / unit); };
  auto point = [&](float x, float y, float z) {
    std::string p(1, '[');  // appended, not "[" + ...: GCC 12 warns on that (-Wrestrict)
    p.append(n(x)).append(",").append(n(y)).append(",").append(n(z)).append("]");
    return p;
  };
  return R"({"camera": {"position": )" + point(-3, 1.2f, 4) + R"(, "look_at": )" +
         point(0, 0.6f, 0) + R"(, "vfov_deg": 50, "width": 12, "height": 12},
    "render": {"mode": "direct", "spp": 1, "seed": 3},
    "materials": {"floor": {"albedo": 0.5}},
    "shapes": [{"type": "quad", "corners": [)" +
         point(-4, 0, -4) + "," + point(4, 0, -4) + "," + point(4, 0, 4) + "," + point(-4, 0, 4) +
         R"(], "material": "floor"}],
    "lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 3}],
    "media": [{"type": "procedural", "kind": "noise", "frequency": )" +
         per(3) + R"(, "min": )" + point(-1, 0, -1) + R"(, "max": )" + point(1, 1.2f, 1) +
         R"(, "sigma_a": )" + per(0.4f) + R"(, "sigma_s": )" + per(2) + R"(},
              {"type": "homogeneous", "min": )" +
         point(-4, 0, -4) + R"(, "max": )" + point(4, 2, 4) + R"(, "sigma_a": )" + per(0.02f) +
         R"(, "sigma_s": )" + per(0.1f) + R"(}],
    "volume_integrator": )" +
         integrator + "}";
}

struct Rendered {
  Image image;
  uint64_t evaluations = 0;
};

Rendered render(float unit, const std::string& integrator) {
  const Scene scene = parseScene(sceneIn(unit, integrator), "/tmp/medium-scale-units.json");
  Report report;
  Rendered r;
  r.image = renderScene(scene.job(), report);
  r.evaluations = report.counts["medium_evals"];
  return r;
}

TEST(RelativeSteps, ASceneRendersTheSameInAnyUnits) {
  for (const char* solver : {"rk4", "simpson", "auto"}) {
    const std::string relative = std::string(R"({"solver": ")") + solver + "\"}";
    const Rendered metres = render(1.0f, relative), scaled = render(kUnit, relative);
    ASSERT_GT(metres.evaluations, 10000u) << solver;
    EXPECT_EQ(scaled.evaluations, metres.evaluations) << solver;
    ASSERT_EQ(scaled.image.pixels.size(), metres.image.pixels.size());
    for (size_t i = 0; i < metres.image.pixels.size(); ++i)
      ASSERT_EQ(scaled.image.pixels[i], metres.image.pixels[i]) << solver << " pixel " << i;
  }
  // One absolute step: 64x the steps in the scaled scene.
  const std::string absolute = R"({"solver": "rk4", "step": 0.4})";
  const Rendered metres = render(1.0f, absolute), scaled = render(kUnit, absolute);
  EXPECT_GT(scaled.evaluations, 20 * metres.evaluations);
}

}  // namespace
}  // namespace lvox
