// How camera rays blend the lvoxels' direct light between cell centres
// (pointcloud/lvoxel_light.h, LvoxelLightBlend).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pointcloud/lvoxel_light.h"

namespace lvox {
namespace {

// A row of unit cells along x (centres at 0.5, 1.5, ...), one delta light and one phase.
// Cell i gets the delta light's transmittance visible[i] x exp(-depth[i]) and the light
// towards the camera 3 x that (its clear value 3 where visible).
LvoxelLight row(const std::vector<float>& depth, const std::vector<bool>& visible,
                LvoxelLightBlend blend) {
  LvoxelLight light(LvoxelGrid{Vec3(0.0f), 1.0f, {static_cast<long>(depth.size()), 1, 1}});
  for (size_t i = 0; i < depth.size(); ++i) light.occupy(static_cast<long>(i));
  light.setChannels(1, 1);
  light.setBlend(blend);
  for (uint32_t i = 0; i < depth.size(); ++i) {
    const float clear = visible[i] ? 1.0f : 0.0f;
    light.transmittanceClear(i)[0] = RGB(clear);
    light.transmittance(i)[0] = RGB(clear * std::exp(-depth[i]));
    light.towardsCameraClear(i)[0] = RGB(3.0f * clear);
    light.towardsCamera(i)[0] = RGB(3.0f * clear * std::exp(-depth[i]));
  }
  light.finishCameraChannels();
  return light;
}

LvoxelLightSample at(const LvoxelLight& light, float x) {
  LvoxelLightSample s;
  EXPECT_TRUE(light.interpolate(Vec3(x, 0.5f, 0.5f), s));
  return s;
}

// Light falling as exp(-2 x) through a thick medium (optical depth 2 between centres):
// the exponential blend gives it exactly between the centres; the linear one gives
// cosh(1) = 1.543 times too much halfway.
TEST(LvoxelLight, TheExponentialBlendFollowsAnExponentialFalloff) {
  const std::vector<float> depth{1.0f, 3.0f, 5.0f, 7.0f};
  const std::vector<bool> visible(4, true);
  const LvoxelLight exponential = row(depth, visible, LvoxelLightBlend::kExponential);
  const LvoxelLight linear = row(depth, visible, LvoxelLightBlend::kLinear);
  for (float x : {0.75f, 1.0f, 1.3f, 2.0f, 2.9f, 3.25f}) {
    const float exact = std::exp(-2.0f * x);
    const LvoxelLightSample s = at(exponential, x);
    EXPECT_NEAR(s.transmittance[0].x, exact, 1e-5f * exact) << x;
    EXPECT_NEAR(s.towardsCamera[0].y, 3.0f * exact, 3e-5f * exact) << x;
  }
  const float exact = std::exp(-4.0f);
  EXPECT_NEAR(at(linear, 2.0f).transmittance[0].z / exact, std::cosh(1.0f), 1e-4f);
  // At a centre both give the centre's own light.
  EXPECT_FLOAT_EQ(at(linear, 1.5f).transmittance[0].x, at(exponential, 1.5f).transmittance[0].x);
}

// A surface's shadow is in the clear part, which blends linearly as before: a quarter of
// the way from a lit centre to a shadowed one keeps 3/4 of the lit centre's light, with
// the lit centre's depth (the shadowed centre has none to give).
TEST(LvoxelLight, GeometryShadowsStillBlendLinearly) {
  const LvoxelLight light =
      row({2.0f, 0.0f, 1.0f}, {true, false, true}, LvoxelLightBlend::kExponential);
  EXPECT_NEAR(at(light, 0.75f).transmittance[0].x, 0.75f * std::exp(-2.0f), 1e-6f);
  EXPECT_NEAR(at(light, 2.25f).towardsCamera[0].x, 3.0f * 0.75f * std::exp(-1.0f), 1e-5f);
  EXPECT_EQ(at(light, 1.5f).transmittance[0].x, 0.0f);
}

// Light that no sample reaches through the medium (a transmittance that underflowed)
// stays dark at its centre and does not turn into NaN or light between centres.
TEST(LvoxelLight, AnUnderflowedTransmittanceStaysDark) {
  const LvoxelLight light = row({1.0f, 200.0f}, {true, true}, LvoxelLightBlend::kExponential);
  const LvoxelLightSample mid = at(light, 1.0f);
  EXPECT_TRUE(std::isfinite(mid.transmittance[0].x));
  EXPECT_LT(mid.transmittance[0].x, 1e-15f);
  EXPECT_LT(at(light, 1.5f).transmittance[0].x, 1e-30f);
}

}  // namespace
}  // namespace lvox
