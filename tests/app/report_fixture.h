#pragma once
// Inputs for the `lvox report` tests: small EXRs with known pixels (one with AOV layers),
// a sweep, render reports and a convergence curve made by the lvox binary itself.
#include <cmath>
#include <filesystem>
#include <string>

#include "app/run_lvox.h"
#include "src/core/exr_channels.h"
#include "src/core/image_io.h"
#include "test_util.h"

namespace lvox::test {

inline constexpr int kWidth = 24, kHeight = 16;

// The reference and the render differ everywhere (the render is 1.5 times brighter).
inline RGB referencePixel(int x, int y) {
  return RGB(0.2f + 0.01f * static_cast<float>(x), 0.3f + 0.01f * static_cast<float>(y), 0.15f);
}
inline RGB renderPixel(int x, int y) { return referencePixel(x, y) * 1.5f; }
inline RGB albedoPixel(int x, int y) {
  return RGB(0.5f, 0.25f + 0.02f * static_cast<float>(x), 0.125f + 0.01f * static_cast<float>(y));
}
inline float depthPixel(int x, int y) { return 0.25f * static_cast<float>(x + y); }

inline void writeReference(const std::filesystem::path& path) {
  Image ref(kWidth, kHeight);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) ref.at(x, y) = referencePixel(x, y);
  writeExr(path.string(), ref);
}

// The render with two AOV layers: albedo (RGB) and depth (Z).
inline void writeLayeredRender(const std::filesystem::path& path) {
  ExrChannels c;
  c.width = kWidth;
  c.height = kHeight;
  c.names = {"B", "G", "R", "albedo.B", "albedo.G", "albedo.R", "depth.Z"};
  c.planes.assign(c.names.size(), std::vector<float>(kWidth * kHeight));
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const size_t i = static_cast<size_t>(y * kWidth + x);
      const RGB v = renderPixel(x, y), a = albedoPixel(x, y);
      for (int k = 0; k < 3; ++k) {
        c.planes[static_cast<size_t>(2 - k)][i] = v[k];
        c.planes[static_cast<size_t>(5 - k)][i] = a[k];
      }
      c.planes[6][i] = depthPixel(x, y);
    }
  writeExrChannels(path.string(), c);
}

// A point light in fog, 12x12 pixels: sweeps and renders of it take well under a second.
inline const char* kFogScene = R"({
  "camera": {"position": [0, 0, 0], "look_at": [1, 0, 0], "vfov_deg": 40, "width": 12, "height": 12},
  "render": {"mode": "direct", "spp": 1},
  "lights": [{"type": "point", "position": [2, 1.5, 0], "intensity": 10}],
  "media": [{"type": "homogeneous", "min": [-1, -2, -2], "max": [5, 2, 2], "sigma_a": 0.3, "sigma_s": 0.4}],
  "volume_integrator": {"step": 0.1}
})";

}  // namespace lvox::test
