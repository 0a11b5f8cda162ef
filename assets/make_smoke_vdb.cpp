// Writes assets/smoke_plume.vdb: a deterministic procedural smoke plume (float grid
// "density" in [0, 1], voxel size 0.05 m, 64 x 128 x 64 voxels, standing on the origin:
// the base centre is at world (0, 0, 0) and it rises along +y to 6.4 m).
//   build/make_smoke_vdb assets/smoke_plume.vdb
#include <openvdb/openvdb.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace {

// A smooth pseudo-turbulence: a few octaves of products of sines (deterministic).
float turbulence(float x, float y, float z) {
  float sum = 0.0f, amplitude = 0.5f, f = 0.09f;
  for (int octave = 0; octave < 4; ++octave) {
    sum += amplitude * std::sin(f * x + 1.7f * static_cast<float>(octave)) *
           std::sin(f * 0.8f * y + 0.9f * static_cast<float>(octave)) *
           std::sin(f * z + 2.3f * static_cast<float>(octave) + 0.5f * std::sin(0.05f * y));
    amplitude *= 0.5f;
    f *= 2.1f;
  }
  return sum;  // in about [-0.94, 0.94]
}

float smoothstep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

float plumeDensity(int ii, int j, int kk) {
  const float y = static_cast<float>(j);
  const float i = static_cast<float>(ii), k = static_cast<float>(kk);
  const float h = y / 128.0f;
  // The column drifts and widens as it rises.
  const float cx = 6.0f * std::sin(0.045f * y) + 2.5f * std::sin(0.13f * y + 1.0f);
  const float cz = 5.0f * std::sin(0.038f * y + 2.0f) + 2.0f * std::sin(0.11f * y);
  const float radius = 5.0f + 19.0f * h;
  const float dx = i - cx, dz = k - cz;
  const float r = std::sqrt(dx * dx + dz * dz) / radius;
  const float shape = 1.0f - smoothstep(0.45f, 1.0f, r + 0.35f * turbulence(i, y, k));
  const float vertical = smoothstep(0.0f, 6.0f, y) * (1.0f - smoothstep(100.0f, 127.0f, y));
  const float billow = 0.75f + 0.25f * turbulence(2.0f * i + 40.0f, 1.5f * y, 2.0f * k);
  return std::clamp(shape * vertical * billow, 0.0f, 1.0f);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_smoke_vdb OUT.vdb\n");
    return 2;
  }
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("density");
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(0.05));
  auto accessor = grid->getAccessor();
  for (int k = -32; k < 32; ++k)
    for (int j = 0; j < 128; ++j)
      for (int i = -32; i < 32; ++i) {
        const float d = plumeDensity(i, j, k);
        if (d > 1e-3f) accessor.setValue(openvdb::Coord(i, j, k), d);
      }
  grid->pruneGrid();
  const std::string tmp = std::string(argv[1]) + ".tmp";
  openvdb::io::File file(tmp);
  file.write({grid});
  file.close();
  if (std::rename(tmp.c_str(), argv[1]) != 0) {
    std::perror("rename");
    return 1;
  }
  std::printf("%s: %llu active voxels\n", argv[1],
              static_cast<unsigned long long>(grid->activeVoxelCount()));
  return 0;
}
