#pragma once
// What a render reads: the world, the media descriptions and the settings of each library
// that takes part, as the scene loader composed them (src/scene). A view: it owns nothing.
#include <string>
#include <vector>

#include "pointcloud/pointcloud_settings.h"
#include "src/render/render_settings.h"
#include "src/world/world.h"
#include "volume/media/medium_desc.h"
#include "volume/volume_settings.h"

namespace lvox {

struct RenderJob {
  const std::string& sceneFile;  // names the source of settings checked only after loading
  const World& world;
  const std::vector<MediumDesc>& media;
  const RenderSettings& render;
  const VolumeSettings& volume;
  const PointCloudSettings& pointcloud;
};

}  // namespace lvox
