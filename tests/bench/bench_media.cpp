// Medium lookups per second on the generated smoke plume, per interpolation.
//   build/tests/bench/lvox_bench --benchmark_filter=MediumLookup
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "src/core/rng.h"
#include "src/scene/scene_loader.h"
#include "volume/media/media_set.h"

namespace lvox {
namespace {

MediaSet smokeMedia(const std::string& interpolation) {
  const std::string text = std::string(R"({"camera": {"position": [0,0,-5], "look_at": [0,0,0]},
    "volume_integrator": {"interpolation": ")") +
                           interpolation + R"("},
    "media": [{"type": "vdb", "file": ")" +
                           LVOX_SOURCE_DIR + R"(/assets/smoke_plume.vdb"}]})";
  std::vector<std::string> warnings;
  const Scene scene = parseScene(text, "bench.json");
  return MediaSet::build(scene.media, scene.volume.interpolation, warnings);
}

void MediumLookup(benchmark::State& state, const char* interpolation) {
  const MediaSet media = smokeMedia(interpolation);
  const Bounds3 b = media.bounds();
  std::vector<Vec3> points(4096);
  Rng rng(1, 2);
  for (Vec3& p : points)
    p = b.lo + mul(b.diagonal(), Vec3(rng.uniform(), rng.uniform(), rng.uniform()));
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(media.at(points[i++ & 4095]));
  }
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK_CAPTURE(MediumLookup, nearest, "nearest");
BENCHMARK_CAPTURE(MediumLookup, trilinear, "trilinear");
BENCHMARK_CAPTURE(MediumLookup, tricubic, "tricubic");

}  // namespace
}  // namespace lvox
