#pragma once
// The scene model: what a scene file describes, after validation. Geometry is flattened
// into one triangle mesh in world space; media are kept as descriptions that the volume
// library turns into media objects.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "src/core/math.h"

namespace lvox {

struct Camera {
  Vec3 position{0, 0, 5};
  Vec3 lookAt{0, 0, 0};
  Vec3 up{0, 1, 0};
  float vfovDeg = 45.0f;
  int width = 512;
  int height = 512;

  // Ray through image-plane position (px, py) in pixels from the top-left corner.
  Ray generateRay(float px, float py) const;
};

struct Material {
  std::string name;
  RGB albedo{0.8f, 0.8f, 0.8f};
  RGB emission{0.0f, 0.0f, 0.0f};  // emitted radiance, W/(m^2 sr)
  bool isEmissive() const { return !isBlack(emission); }
};

// All triangles of the scene in world space; one material index per triangle.
struct TriangleMesh {
  std::vector<Vec3> positions;
  std::vector<uint32_t> indices;           // 3 per triangle
  std::vector<uint32_t> triangleMaterial;  // 1 per triangle
  size_t triangleCount() const { return triangleMaterial.size(); }
  Vec3 vertex(size_t tri, int k) const { return positions[indices[3 * tri + k]]; }
  // Sum of the triangles' areas, accumulated in double.
  double area() const {
    double a = 0.0;
    for (size_t t = 0; t < triangleCount(); ++t)
      a += 0.5 * length(cross(vertex(t, 1) - vertex(t, 0), vertex(t, 2) - vertex(t, 0)));
    return a;
  }
};

enum class LightType { Directional, Point, Spot, Environment };

struct Light {
  LightType type = LightType::Point;
  Vec3 position{0, 0, 0};
  Vec3 direction{0, -1, 0};  // direction of travel (directional, spot axis), unit
  RGB intensity{0, 0, 0};    // W/sr for point/spot, W/m^2 irradiance for directional,
                             // W/(m^2 sr) radiance for the environment
  float coneDeg = 30.0f;     // spot: angle from the axis to the edge
  float falloffDeg = 5.0f;   // spot: width of the smooth edge

  // Spot falloff: 1 inside cone-falloff, smoothstep in cos to 0 at the cone edge.
  float spotFactor(const Vec3& dirFromLight) const;
};

enum class MediumType { Vdb, Homogeneous, Procedural };
enum class ProceduralKind { Constant, LinearRamp, GaussianBlob, Noise };

struct MediumDesc {
  MediumType type = MediumType::Homogeneous;
  std::string field;  // "media[i]", for error messages
  // vdb
  std::string file;  // absolute path
  std::string grid = "density";
  std::string emissionGrid;  // optional
  float densityScale = 1.0f;
  RGB albedo{0.8f, 0.8f, 0.8f};
  RGB emission{0.0f, 0.0f, 0.0f};  // Le multiplied by sigma_a (and the emission grid)
  Transform transform;
  // homogeneous and procedural: the box
  Vec3 boxMin{-1, -1, -1};
  Vec3 boxMax{1, 1, 1};
  RGB sigmaA{0, 0, 0};
  RGB sigmaS{0, 0, 0};
  // procedural (density multiplies sigma_a/sigma_s of the box)
  ProceduralKind procedural = ProceduralKind::Constant;
  Vec3 gradient{0, 0, 0};  // linear ramp: density = 1 + dot(gradient, p - boxMin)
  Vec3 center{0, 0, 0};    // gaussian blob centre
  float radius = 1.0f;     // gaussian blob std-dev
  float frequency = 1.0f;  // noise: cycles per unit
  // phase function
  std::string phase = "hg";  // isotropic | hg | schlick
  float g = 0.0f;
};

struct VolumeIntegratorSettings {
  std::string solver = "auto";  // or any method of volume/rte/method.h
  float step = 0.1f;            // scene units
  float tolerance = 1e-3f;
  float minStep = 1e-4f;
  float maxStep = 1.0f;
  std::string interpolation = "trilinear";  // nearest | trilinear | tricubic
  std::string sampling = "none";            // none | distance | equiangular
  uint32_t maxEvaluations = 100000;         // per ray segment, then degrade gracefully
  bool majorantGrid = true;  // mc: per-block majorants of VDB grids (false: one per medium)
};

struct PointCloudSettings {
  float surfelSpacing = 0.0f;              // 0: derived from the total surface area
  int targetSurfels = 100000;              // used to derive the spacing when it is 0
  std::string surfelSampler = "uniform";   // uniform | camera
  float lvoxelSpacing = 0.0f;              // 0: derived from the medium size
  int lvoxelSamples = 2;                   // jittered samples per axis averaged per lvoxel
  int lvoxelGatherSamples = 16;            // sphere rays per lvoxel and scattering pass
  int bounces = 24;                        // interreflection passes (surfels and lvoxels)
  float burialReach = 4.0f;                // surfel spacings; 0 keeps buried surfels
  std::string gatherVisibility = "cloud";  // cloud (first surfel disk) | rays (ray traced)
  int surfelGatherSamples = 4;             // hemisphere rays per surfel side and pass
  int gatherSamples = 64;                  // gather rays per pixel (split over its samples)
  int gatherSpacing = 4;                   // pixels between final gathers; 1: every camera hit
  float gatherFilter = 3.0f;               // tent half-width over final gathers, in gathers
  float lvoxelClusterSolidAngle = 0.03f;   // sr; the same for nodes holding lvoxels only
  float clusterSolidAngle = 0.0f;          // sr; 0 = every element exactly
};

struct RenderSettings {
  std::string mode = "pcb";
  int spp = 4;
  int maxBounces = 8;
  uint64_t seed = 1;
  int areaLightSamples = 16;   // shadow rays per area light (and environment) at a surface point
  int mediumLightSamples = 1;  // the same at each medium evaluation (fixed along a camera ray)
  int threads = 0;             // 0: all cores
};

struct Scene {
  std::string path;  // the scene file, for messages
  Camera camera;
  RenderSettings render;
  std::vector<Material> materials;
  TriangleMesh mesh;
  std::vector<Light> lights;
  std::vector<MediumDesc> media;
  VolumeIntegratorSettings volume;
  PointCloudSettings pointcloud;
  std::vector<std::string> inputFiles;  // every file read, so outputs never overwrite one

  Bounds3 bounds() const;
};

}  // namespace lvox
