// Makes a production-sized test volume on demand (never committed): a float grid
// upsampled by an integer factor from a source grid (the WDAS cloud at 1/16 resolution by
// default) with value-noise detail added at the new resolution, covering the same world
// space, so a scene that shows the source shows the large grid the same way.
//   build/make_large_vdb SOURCE.vdb OUT.vdb [FACTOR (default 10)] [GRID (default density)]
// At factor 10 the WDAS 1/16 cloud (415,642 active voxels) becomes 3.6e8 active voxels
// (tests/bench/large_volume.sh reports the exact count and OpenVDB's memUsage).
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <unordered_set>
#include <vector>

namespace {

using openvdb::Coord;
using LeafT = openvdb::FloatTree::LeafNodeType;

// Deterministic value noise in [-1, 1] on a lattice of `period` voxels (smoothstep-blended
// hashes of the lattice corners).
float hashUnit(int x, int y, int z) {
  uint32_t h = static_cast<uint32_t>(x) * 73856093u ^ static_cast<uint32_t>(y) * 19349663u ^
               static_cast<uint32_t>(z) * 83492791u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return static_cast<float>(h & 0xffffffu) / static_cast<float>(0xffffff) * 2.0f - 1.0f;
}

float valueNoise(const Coord& o, int period) {
  auto floorDiv = [](int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); };
  const int cx = floorDiv(o.x(), period), cy = floorDiv(o.y(), period), cz = floorDiv(o.z(), period);
  auto smooth = [](float t) { return t * t * (3.0f - 2.0f * t); };
  const float p = static_cast<float>(period);
  const float tx = smooth(static_cast<float>(o.x() - cx * period) / p);
  const float ty = smooth(static_cast<float>(o.y() - cy * period) / p);
  const float tz = smooth(static_cast<float>(o.z() - cz * period) / p);
  float sum = 0.0f;
  for (int c = 0; c < 8; ++c) {
    const float w = (c & 1 ? tx : 1.0f - tx) * (c & 2 ? ty : 1.0f - ty) * (c & 4 ? tz : 1.0f - tz);
    sum += w * hashUnit(cx + (c & 1), cy + ((c >> 1) & 1), cz + ((c >> 2) & 1));
  }
  return sum;
}

// Two octaves of detail: the large grid is not a smooth upsampling of the small one.
float detail(const Coord& o) { return 0.65f * valueNoise(o, 7) + 0.35f * valueNoise(o, 3); }

int floorDiv8(int a) { return a >= 0 ? a / 8 : -((-a + 7) / 8); }

struct CoordHash {
  size_t operator()(const Coord& c) const {
    return static_cast<size_t>(c.x()) * 73856093u ^ static_cast<size_t>(c.y()) * 19349663u ^
           static_cast<size_t>(c.z()) * 83492791u;
  }
};

int run(const std::string& in, const std::string& out, int factor, const std::string& name) {
  const auto start = std::chrono::steady_clock::now();
  openvdb::initialize();
  openvdb::io::File file(in);
  file.open();
  auto source = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(name));
  file.close();
  if (!source) {
    std::fprintf(stderr, "make_large_vdb: %s: grid '%s' is not a float grid\n", in.c_str(),
                 name.c_str());
    return 1;
  }
  // Output leaves: every leaf the source's leaves (and their interpolation reach) cover.
  std::unordered_set<Coord, CoordHash> leafSet;
  for (auto leaf = source->tree().cbeginLeaf(); leaf; ++leaf) {
    const Coord l = leaf->origin();
    for (int z = floorDiv8((l.z() - 1) * factor); z <= floorDiv8((l.z() + 9) * factor - 1); ++z)
      for (int y = floorDiv8((l.y() - 1) * factor); y <= floorDiv8((l.y() + 9) * factor - 1); ++y)
        for (int x = floorDiv8((l.x() - 1) * factor); x <= floorDiv8((l.x() + 9) * factor - 1); ++x)
          leafSet.insert(Coord(x * 8, y * 8, z * 8));
  }
  const std::vector<Coord> origins(leafSet.begin(), leafSet.end());
  leafSet.clear();
  std::vector<std::unique_ptr<LeafT>> leaves(origins.size());
  const double inv = 1.0 / factor, shift = 0.5 / factor - 0.5;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, origins.size(), 256), [&](const auto& range) {
    auto acc = source->getConstAccessor();
    for (size_t n = range.begin(); n != range.end(); ++n) {
      auto leaf = std::make_unique<LeafT>(origins[n], 0.0f, false);
      bool any = false;
      for (openvdb::Index i = 0; i < LeafT::SIZE; ++i) {
        const Coord o = leaf->offsetToGlobalCoord(i);
        const openvdb::Vec3d s(o.x() * inv + shift, o.y() * inv + shift, o.z() * inv + shift);
        const float base = openvdb::tools::BoxSampler::sample(acc, s);
        if (!(base > 0.0f)) continue;
        const float d = base * std::max(0.0f, 1.0f + 0.8f * detail(o));
        if (d > 0.0f) {
          leaf->setValueOn(i, d);
          any = true;
        }
      }
      if (any) leaves[n] = std::move(leaf);
    }
  });
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName(name);
  for (auto& leaf : leaves)
    if (leaf) grid->tree().addLeaf(leaf.release());
  // Output voxel o is source voxel (o + 0.5) / factor - 0.5: the same world space.
  auto transform = source->transform().copy();
  transform->preTranslate(openvdb::Vec3d(shift));
  transform->preScale(inv);
  grid->setTransform(transform);
  const openvdb::Vec3d check = grid->indexToWorld(openvdb::Vec3d(3.0)) -
                               source->indexToWorld(openvdb::Vec3d(3.0 * inv + shift));
  if (check.length() > 1e-6 * source->voxelSize()[0]) {
    std::fprintf(stderr, "make_large_vdb: transform mismatch (%g)\n", check.length());
    return 1;
  }
  openvdb::io::File output(out);
  output.setCompression(openvdb::io::COMPRESS_ACTIVE_MASK);  // fast to write and read
  output.write({grid});
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s: %llu active voxels (source %llu, factor %d), memUsage %.1f MB, %.1f s\n",
              out.c_str(), static_cast<unsigned long long>(grid->activeVoxelCount()),
              static_cast<unsigned long long>(source->activeVoxelCount()), factor,
              static_cast<double>(grid->memUsage()) / 1e6, seconds);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: make_large_vdb SOURCE.vdb OUT.vdb [FACTOR] [GRID]\n");
    return 2;
  }
  const int factor = argc > 3 ? std::atoi(argv[3]) : 10;
  if (factor < 1 || factor > 64) {
    std::fprintf(stderr, "make_large_vdb: FACTOR must be 1..64\n");
    return 2;
  }
  try {
    return run(argv[1], argv[2], factor, argc > 4 ? argv[4] : "density");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_large_vdb: %s\n", e.what());
    return 1;
  }
}
