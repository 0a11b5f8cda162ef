// AOV layers (src/render/layers.h) against closed forms: a Lambertian floor of albedo rho
// and emission Le under a directional light of irradiance E straight down has direct
// rho E / pi and emission Le; an escaping ray sees the environment; a homogeneous emissive
// slab adds sigma_a Le (1 - e^{-sigma_t d}) / sigma_t of emission and oracle 2.1's single
// scattering. The radiance layers add up to the beauty in every mode.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>

#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"

namespace lvox {
namespace {

constexpr double kPi = std::numbers::pi;

RenderResult renderLayers(const std::string& text, Mode mode, const std::string& layers,
                          int spp = 4) {
  Scene scene = parseScene(text, "/tmp/layers-test.json");
  scene.render.mode = mode;
  RenderPlan plan;
  plan.spp = spp;
  if (!layers.empty()) plan.layers = LayerSet::parse(layers, mode == Mode::kMc, "test");
  Report report;
  return renderScene(scene.job(), plan, report);
}

// The value of channel `name` (e.g. "direct.R") at pixel (x, y).
float channel(const RenderResult& r, const std::string& name, int x = 0, int y = 0) {
  for (const ExtraChannel& c : r.layers)
    if (c.name == name) return c.values[static_cast<size_t>(y) * r.image.width + x];
  ADD_FAILURE() << "no channel " << name;
  return NAN;
}

RGB layer(const RenderResult& r, const std::string& name, int x = 0, int y = 0) {
  return {channel(r, name + ".R", x, y), channel(r, name + ".G", x, y),
          channel(r, name + ".B", x, y)};
}

// A 1 x 1 camera 3 units above a large floor quad, looking straight down (or up, `up`),
// under a directional light and a sky of radiance `sky`.
std::string floorScene(bool up, float sky) {
  std::ostringstream s;
  s << R"({"camera": {"position": [0, 3, 0], "look_at": [0, )" << (up ? 10 : 0)
    << R"(, 0], "up": [0, 0, -1], "vfov_deg": 0.001, "width": 1, "height": 1},
   "render": {"max_bounces": 4},
   "materials": {"floor": {"albedo": [0.5, 0.25, 0.8], "emission": [0.1, 0.2, 0.3]}},
   "shapes": [{"type": "quad", "corners": [[-50,0,-50],[50,0,-50],[50,0,50],[-50,0,50]], "material": "floor"}],
   "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2},
              {"type": "environment", "radiance": )"
    << sky << "}]}";
  return s.str();
}

void expectNear(const RGB& got, const RGB& expected, double tol, const std::string& what) {
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(got[c], expected[c], tol * std::abs(expected[c]) + 1e-6)
        << what << " channel " << c;
}

TEST(Layers, FirstSurfaceLayersHaveTheirClosedForms) {
  const RGB rho(0.5f, 0.25f, 0.8f), emission(0.1f, 0.2f, 0.3f);
  for (Mode mode : {Mode::kDirect, Mode::kPcb, Mode::kPcbSurfels, Mode::kMc}) {
    const std::string m(modeName(mode));
    const RenderResult r = renderLayers(floorScene(false, 0.0f), mode, "all");
    // The floor faces the light: direct rho E / pi, exact (one delta light, no media).
    expectNear(layer(r, "direct"), rho * static_cast<float>(2.0 / kPi), 1e-5, m + " direct");
    expectNear(layer(r, "emission"), emission, 1e-6, m + " emission");
    expectNear(layer(r, "albedo"), rho, 1e-6, m + " albedo");
    // Nothing but the floor, under a black sky: no indirect light.
    expectNear(layer(r, "indirect"), RGB(0.0f), 0.0, m + " indirect");
    expectNear(layer(r, "environment"), RGB(0.0f), 0.0, m + " environment");
    expectNear(layer(r, "volume"), RGB(0.0f), 0.0, m + " volume");
    EXPECT_NEAR(channel(r, "normal.X"), 0.0f, 1e-6) << m;
    EXPECT_NEAR(channel(r, "normal.Y"), 1.0f, 1e-6) << m;
    EXPECT_NEAR(channel(r, "depth.Z"), 3.0f, 1e-4) << m;
    EXPECT_EQ(channel(r, "coverage.Y"), 1.0f) << m;
    const RGB sum = layer(r, "direct") + layer(r, "indirect") + layer(r, "emission");
    expectNear(r.image.at(0, 0), sum, 1e-5, m + " beauty");
  }
}

// The sky's light on a surface is direct light in every mode, though pcb with traced
// gathers finds it with its final gathers' escaping rays and not with light samples: the
// open floor sees all of the sky, so every estimate is exact, rho (E / pi + L_sky).
TEST(Layers, SkyLightOnASurfaceIsDirectInEveryMode) {
  const RGB rho(0.5f, 0.25f, 0.8f);
  const RGB expected = rho * static_cast<float>(2.0 / kPi + 0.7);
  for (Mode mode : {Mode::kDirect, Mode::kPcb, Mode::kPcbSurfels, Mode::kMc}) {
    const std::string m(modeName(mode));
    const RenderResult r = renderLayers(floorScene(false, 0.7f), mode, "direct,indirect");
    expectNear(layer(r, "direct"), expected, 1e-5, m + " direct");
    expectNear(layer(r, "indirect"), RGB(0.0f), 0.0, m + " indirect");
  }
}

TEST(Layers, EscapingRayIsEnvironmentOnly) {
  for (Mode mode : {Mode::kDirect, Mode::kPcb, Mode::kMc}) {
    const std::string m(modeName(mode));
    const RenderResult r = renderLayers(floorScene(true, 0.7f), mode, "all");
    expectNear(layer(r, "environment"), RGB(0.7f), 1e-6, m + " environment");
    for (const char* zero : {"direct", "indirect", "volume", "emission", "albedo"})
      expectNear(layer(r, zero), RGB(0.0f), 0.0, m + " " + zero);
    EXPECT_EQ(channel(r, "depth.Z"), 0.0f) << m;
    EXPECT_EQ(channel(r, "coverage.Y"), 0.0f) << m;
    EXPECT_EQ(channel(r, "normal.Y"), 0.0f) << m;
    // One value per sample: no variance; mc writes the layer, the other modes have none.
    if (mode == Mode::kMc) expectNear(layer(r, "variance"), RGB(0.0f), 0.0, "variance");
  }
}

// Oracle 2.1 with emission: a horizontal camera ray through 55 units of a homogeneous
// slab with sigma_a = 0.05 (emission Le = 3), sigma_s = 0.1, lit by a tilted light.
TEST(Layers, MediaSplitIntoEmissionAndInScatter) {
  const std::string scene = R"({
    "camera": {"position": [-5, 0.5, 0], "look_at": [1, 0.5, 0], "vfov_deg": 0.001, "width": 1, "height": 1},
    "render": {"spp": 1},
    "volume_integrator": {"solver": "rk4", "step": 0.5},
    "lights": [{"type": "directional", "direction": [0.6, -0.8, 0], "irradiance": 2}],
    "media": [{"type": "homogeneous", "min": [-50, 0, -50], "max": [50, 1, 50],
               "sigma_a": 0.05, "sigma_s": 0.1, "g": 0.5, "phase": "hg", "emission": 3}]})";
  const double sigmaA = 0.05, sigmaT = 0.15, sigmaS = 0.1, g = 0.5, cosTheta = -0.6, s0 = 0.5 / 0.8,
               d = 55.0;
  const double p = (1 - g * g) / (4 * kPi * std::pow(1 + g * g - 2 * g * cosTheta, 1.5));
  const double inScatter =
      sigmaS * p * 2.0 * std::exp(-sigmaT * s0) * (1 - std::exp(-sigmaT * d)) / sigmaT;
  const double emission = sigmaA * 3.0 * (1 - std::exp(-sigmaT * d)) / sigmaT;
  const RenderResult direct = renderLayers(scene, Mode::kDirect, "all", 1);
  // Constant coefficients: rk4 is exact up to rounding and the jittered first step.
  expectNear(layer(direct, "volume"), RGB(static_cast<float>(inScatter)), 1e-4, "volume");
  expectNear(layer(direct, "emission"), RGB(static_cast<float>(emission)), 1e-4, "emission");
  expectNear(direct.image.at(0, 0), layer(direct, "volume") + layer(direct, "emission"), 1e-6,
             "direct beauty");
  EXPECT_EQ(channel(direct, "coverage.Y"), 0.0f);
  // pcb's in-scatter comes from the lvoxels (an approximation), its emission is solved
  // exactly like direct mode's.
  const RenderResult pcb = renderLayers(scene, Mode::kPcb, "volume,emission", 1);
  expectNear(layer(pcb, "emission"), RGB(static_cast<float>(emission)), 1e-4, "pcb emission");
  expectNear(pcb.image.at(0, 0), layer(pcb, "volume") + layer(pcb, "emission"), 1e-6, "pcb beauty");
  EXPECT_EQ(pcb.layers.size(), 6u);  // only the layers asked for
}

// Every pixel of a small scene with a surface, an emitter, fog and a sky: the five radiance
// layers add up to the beauty in every mode (up to float rounding of the sums).
TEST(Layers, RadianceLayersAddUpToTheBeauty) {
  const std::string scene = R"({
    "camera": {"position": [0, 1.5, 4], "look_at": [0, 0.5, 0], "vfov_deg": 50, "width": 20, "height": 14},
    "render": {"max_bounces": 3},
    "materials": {"white": {"albedo": 0.7}, "lamp": {"albedo": 0.2, "emission": 4}},
    "shapes": [{"type": "quad", "corners": [[-2,0,-2],[2,0,-2],[2,0,2],[-2,0,2]], "material": "white"},
               {"type": "box", "min": [-0.3,0,-0.3], "max": [0.3,0.6,0.3], "material": "lamp"}],
    "lights": [{"type": "directional", "direction": [0.3, -1, -0.2], "irradiance": 3},
               {"type": "environment", "radiance": 0.2}],
    "media": [{"type": "homogeneous", "min": [-1.5, 0, -1.5], "max": [1.5, 1.2, 1.5],
               "sigma_a": 0.1, "sigma_s": 0.4, "emission": 0.5}]})";
  for (Mode mode : {Mode::kDirect, Mode::kPcb, Mode::kMc}) {
    const std::string m(modeName(mode));
    const RenderResult r = renderLayers(scene, mode, "direct,indirect,volume,emission,environment");
    double volume = 0.0, emission = 0.0;
    for (int y = 0; y < r.image.height; ++y)
      for (int x = 0; x < r.image.width; ++x) {
        const RGB sum = layer(r, "direct", x, y) + layer(r, "indirect", x, y) +
                        layer(r, "volume", x, y) + layer(r, "emission", x, y) +
                        layer(r, "environment", x, y);
        expectNear(r.image.at(x, y), sum, 1e-5,
                   m + " pixel " + std::to_string(x) + "," + std::to_string(y));
        volume += layer(r, "volume", x, y).x;
        emission += layer(r, "emission", x, y).x;
      }
    // Not a trivial split: the fog and the lamp both show.
    EXPECT_GT(volume, 0.0) << m;
    EXPECT_GT(emission, 0.0) << m;
    // Asking for layers does not change the image, bit for bit.
    const RenderResult plain = renderLayers(scene, mode, "");
    EXPECT_TRUE(plain.layers.empty());
    EXPECT_EQ(plain.image.pixels, r.image.pixels) << m;
  }
}

TEST(Layers, ParseNamesTheValidLayers) {
  EXPECT_EQ(LayerSet::parse("normal,direct", false, "f").toString(), "direct,normal");
  EXPECT_EQ(LayerSet::parse("all", false, "f").toString(),
            "direct,indirect,volume,emission,environment,albedo,normal,depth");
  EXPECT_TRUE(LayerSet::parse("all", true, "f").has(Layer::kVariance));
  try {
    LayerSet::parse("direct,glossy", false, "--layers");
    FAIL() << "accepted an unknown layer";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown layer 'glossy'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("direct, indirect"), std::string::npos) << e.what();
  }
  EXPECT_THROW(LayerSet::parse("direct,", false, "--layers"), InputError);
}

}  // namespace
}  // namespace lvox
