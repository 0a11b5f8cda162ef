#pragma once
// A scene parsed from JSON text with its media built and their scales
// (src/render/medium_scale.h), for tests of what the solvers plan per segment.
#include <memory>
#include <string>
#include <vector>

#include "src/render/medium_scale.h"
#include "src/scene/scene_loader.h"

namespace lvox::test {

struct SceneMedia {
  Scene scene;
  MediaSet media;
  std::unique_ptr<MediumScales> scales;
  explicit SceneMedia(const std::string& text) : scene(parseScene(text, "/tmp/scene-media.json")) {
    std::vector<std::string> warnings;
    media = MediaSet::build(scene.media, scene.volume.interpolation, warnings);
    scales = std::make_unique<MediumScales>(scene.world.bounds(), media);
  }
};

}  // namespace lvox::test
