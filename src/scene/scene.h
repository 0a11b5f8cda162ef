#pragma once
// A scene as its file describes it: the world, the media and the settings of every library,
// each in its library's own types. The scene loader composes it; each consumer receives
// only its piece (a render receives the RenderJob view).
#include <string>
#include <vector>

#include "pointcloud/pointcloud_settings.h"
#include "src/render/render_job.h"
#include "src/render/render_settings.h"
#include "src/world/world.h"
#include "volume/media/medium_desc.h"
#include "volume/volume_settings.h"

namespace lvox {

struct Scene {
  std::string path;  // the scene file, for messages
  World world;
  std::vector<MediumDesc> media;
  RenderSettings render;
  VolumeSettings volume;
  PointCloudSettings pointcloud;
  std::vector<std::string> inputFiles;  // every file read, so outputs never overwrite one

  RenderJob job() const { return {path, world, media, render, volume, pointcloud}; }
};

}  // namespace lvox
