#pragma once
// One-pixel renders for the oracle tests: a scene whose 1x1 camera looks along the one ray
// of a closed form (shared/oracles.md section 2).
#include <string>

#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"

namespace lvox::test {

struct Pixel {
  RGB value;
  Report report;
};

inline Pixel renderPixel(const Scene& scene) {
  Pixel p;
  p.value = renderScene(scene.job(), p.report).at(0, 0);
  return p;
}

// The scene in `text`, rendered in direct mode with the given volume solver settings.
inline Scene directScene(const std::string& text, const std::string& solver, float step,
                         float tolerance, const std::string& sampling = "none") {
  Scene scene = parseScene(text, "/tmp/lvox-pixel-test.json");
  scene.render.mode = Mode::kDirect;
  scene.volume.solver = parseSolver(solver, "test", "solver");
  scene.volume.step = step;
  scene.volume.tolerance = tolerance;
  scene.volume.sampling = rte::parseSampling(sampling, "test", "sampling");
  return scene;
}

}  // namespace lvox::test
