#pragma once
// The point cloud as files other tools open (`lvox render --export-cloud CLOUD.ply|.vdb`):
// every surfel and lvoxel with its position, normal, radius and cached radiance, as the
// render used them (after the direct cache and the interreflection).
//
//  - PLY (binary little-endian; MeshLab, CloudCompare): one `vertex` element per point with
//    float x y z nx ny nz radius radiance_r/g/b back_r/g/b sigma_t, uchar kind (0 surfel, 1
//    lvoxel) and uchar red green blue, the radiance tone-mapped like the PNG preview (so the
//    viewers show colour).
//  - OpenVDB PointDataGrid "points" (Houdini, Blender): P, N, pscale (the radius), Cd (the
//    radiance), radiance_back, sigma_t and kind, in scene units.
//
// Surfels: the normal is the disk's, the radius its disk's (enlarged to cover the surface),
// the radiance the outgoing radiance of its front side, `back` that of its back side.
// Lvoxels: the normal is 0, the radius half the cube's side, the radiance what the cube
// sends along any ray ((sigma_s L_s + sigma_a Le) / sigma_t, isotropic) and `back` the
// same, sigma_t the extinction averaged over the channels. Radiance in W/(m^2 sr).
#include <cstdint>
#include <string>
#include <vector>

#include "pointcloud/gather.h"
#include "pointcloud/point_cloud.h"
#include "src/core/atomic_file.h"
#include "src/core/math.h"

namespace lvox {

enum class CloudPointKind : uint8_t { kSurfel = 0, kLvoxel = 1 };

struct ExportedCloud {
  std::vector<Vec3> position, normal;
  std::vector<float> radius, sigmaT;
  std::vector<RGB> radiance, radianceBack;
  std::vector<CloudPointKind> kind;

  size_t size() const { return position.size(); }
  void add(CloudPointKind k, const Vec3& p, const Vec3& n, float r, const RGB& front,
           const RGB& back, float extinction);
};

// Copies the cloud's elements (surfels first, then lvoxels). A cloud whose surfels leave the
// delta lights to the gathers' hits (`deltaLight`, pcb with traced visibility) gets their
// light added back: the exported radiance is all the light a surfel stands for.
ExportedCloud exportCloud(const PointCloud& cloud, const SurfaceHitLight* deltaLight = nullptr);

// Writes `cloud` to `path` (.ply or .vdb), staged in `set` (published with the render's
// other outputs) or at once when `set` is null.
void writeCloud(const std::string& path, const ExportedCloud& cloud, OutputSet* set = nullptr);

// Throws InputError(path, field, ...) unless `path` ends in .ply or .vdb.
void checkCloudPath(const std::string& path, const std::string& field);

}  // namespace lvox
