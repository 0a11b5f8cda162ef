// Sparse lookups (SparseGrid: the OpenVDB tree through per-thread accessors) against the
// dense copy lvox used to make (a float array over the active box), on the same grid, in
// one run; and the cost of the majorant walks per cell (docs/results.md, "Sparse volumes").
//   build/tests/bench/lvox_sparse_lookups [FILE.vdb [GRID]]
// Default: the WDAS cloud at 1/16 resolution from ../shared/assets (not in the repository).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

#include "src/core/error.h"
#include "src/core/rng.h"
#include "src/core/sampling.h"
#include "volume/media/vdb_loader.h"

namespace lvox {
namespace {

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// The dense design: values over the padded active box, read by plain array indexing.
struct Dense {
  int nx = 0, ny = 0, nz = 0;
  Vec3 origin;
  std::vector<float> values;
  float voxel(int i, int j, int k) const {
    i -= static_cast<int>(origin.x);
    j -= static_cast<int>(origin.y);
    k -= static_cast<int>(origin.z);
    if (i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz) return 0.0f;
    return values[(static_cast<size_t>(k) * ny + j) * nx + i];
  }
  float sample(const Vec3& p, Interpolation interp) const {
    const float fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
    const int i = static_cast<int>(fx), j = static_cast<int>(fy), k = static_cast<int>(fz);
    if (interp == Interpolation::Nearest)
      return voxel(static_cast<int>(std::floor(p.x + 0.5f)),
                   static_cast<int>(std::floor(p.y + 0.5f)),
                   static_cast<int>(std::floor(p.z + 0.5f)));
    if (interp == Interpolation::Trilinear) {
      const float tx = p.x - fx, ty = p.y - fy, tz = p.z - fz;
      auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
      const float c00 = lerp(voxel(i, j, k), voxel(i + 1, j, k), tx);
      const float c10 = lerp(voxel(i, j + 1, k), voxel(i + 1, j + 1, k), tx);
      const float c01 = lerp(voxel(i, j, k + 1), voxel(i + 1, j, k + 1), tx);
      const float c11 = lerp(voxel(i, j + 1, k + 1), voxel(i + 1, j + 1, k + 1), tx);
      return lerp(lerp(c00, c10, ty), lerp(c01, c11, ty), tz);
    }
    auto weights = [](float f, float w[4]) {
      const float f2 = f * f, f3 = f2 * f;
      w[0] = (1.0f - 3.0f * f + 3.0f * f2 - f3) / 6.0f;
      w[1] = (4.0f - 6.0f * f2 + 3.0f * f3) / 6.0f;
      w[2] = (1.0f + 3.0f * f + 3.0f * f2 - 3.0f * f3) / 6.0f;
      w[3] = f3 / 6.0f;
    };
    float wx[4], wy[4], wz[4];
    weights(p.x - fx, wx);
    weights(p.y - fy, wy);
    weights(p.z - fz, wz);
    float sum = 0.0f;
    for (int c = 0; c < 4; ++c) {
      float plane = 0.0f;
      for (int b = 0; b < 4; ++b) {
        float row = 0.0f;
        for (int a = 0; a < 4; ++a) row += wx[a] * voxel(i - 1 + a, j - 1 + b, k - 1 + c);
        plane += wy[b] * row;
      }
      sum += wz[c] * plane;
    }
    return std::max(0.0f, sum);
  }
};

Dense densify(const SparseGrid& g) {
  Bounds3 index;
  const Bounds3 w = g.worldBounds();
  for (int c = 0; c < 8; ++c)
    index.extend(g.worldToIndex().point(
        Vec3(c & 1 ? w.hi.x : w.lo.x, c & 2 ? w.hi.y : w.lo.y, c & 4 ? w.hi.z : w.lo.z)));
  Dense d;
  d.origin = Vec3(std::floor(index.lo.x), std::floor(index.lo.y), std::floor(index.lo.z));
  d.nx = static_cast<int>(std::ceil(index.hi.x) - d.origin.x) + 1;
  d.ny = static_cast<int>(std::ceil(index.hi.y) - d.origin.y) + 1;
  d.nz = static_cast<int>(std::ceil(index.hi.z) - d.origin.z) + 1;
  d.values.resize(static_cast<size_t>(d.nx) * d.ny * d.nz);
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i < d.nx; ++i)
        d.values[(static_cast<size_t>(k) * d.ny + j) * d.nx + i] =
            g.voxel(i + static_cast<int>(d.origin.x), j + static_cast<int>(d.origin.y),
                    k + static_cast<int>(d.origin.z));
  return d;
}

// Index-space lookups: `random` uniform over the box (incoherent), else marching rays
// through it at half-voxel steps (what tracking and the solvers do).
std::vector<Vec3> lookupPoints(const SparseGrid& g, bool random) {
  Bounds3 index;
  const Bounds3 w = g.worldBounds();
  for (int c = 0; c < 8; ++c)
    index.extend(g.worldToIndex().point(
        Vec3(c & 1 ? w.hi.x : w.lo.x, c & 2 ? w.hi.y : w.lo.y, c & 4 ? w.hi.z : w.lo.z)));
  Rng rng(11, 12);
  std::vector<Vec3> points;
  const Vec3 d = index.diagonal();
  if (random) {
    for (int i = 0; i < 2000000; ++i)
      points.push_back(index.lo +
                       Vec3(rng.uniform() * d.x, rng.uniform() * d.y, rng.uniform() * d.z));
    return points;
  }
  while (points.size() < 2000000) {
    const Vec3 from = index.lo + Vec3(rng.uniform() * d.x, rng.uniform() * d.y, 0.0f);
    const Vec3 to = index.lo + Vec3(rng.uniform() * d.x, rng.uniform() * d.y, d.z);
    const Vec3 dir = normalize(to - from);
    for (float t = 0.0f; t < length(to - from); t += 0.5f) points.push_back(from + dir * t);
  }
  return points;
}

// The calling thread's CPU time: time the process is descheduled (other processes on the
// machine) does not count.
double threadSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Nanoseconds per lookup of `a` and `b` over `points`: the best of 7 passes each, the two
// interleaved so that a slow spell of the machine hits both alike.
template <class A, class B>
std::pair<double, double> nanosPerLookup(const std::vector<Vec3>& points, A&& a, B&& b,
                                         double& sumA, double& sumB) {
  double bestA = 1e30, bestB = 1e30;
  const auto pass = [&](auto&& sample, double& best, double& sum) {
    const double start = threadSeconds();
    sum = 0.0;
    for (const Vec3& p : points) sum += sample(p);
    best = std::min(best, threadSeconds() - start);
  };
  for (int rep = 0; rep < 7; ++rep) {
    pass(a, bestA, sumA);
    pass(b, bestB, sumB);
  }
  const double n = static_cast<double>(points.size());
  return {bestA * 1e9 / n, bestB * 1e9 / n};
}

int run(const std::string& file, const std::string& gridName) {
  GridLoadReport report;
  auto start = std::chrono::steady_clock::now();
  const SparseGrid g = loadVdbGrid(file, gridName, Transform(), "grid", report);
  const double loadSeconds = seconds(start);
  start = std::chrono::steady_clock::now();
  const Dense dense = densify(g);
  const double densifySeconds = seconds(start);
  std::printf("%s '%s': %llu active voxels, loaded in %.2f s\n", file.c_str(), gridName.c_str(),
              static_cast<unsigned long long>(report.activeVoxels), loadSeconds);
  std::printf(
      "memory: sparse %.1f MB (value tree %.1f MB + majorant trees), dense %.1f MB "
      "(%dx%dx%d, built in %.2f s)\n",
      static_cast<double>(g.memoryBytes()) / 1e6, static_cast<double>(report.treeBytes) / 1e6,
      static_cast<double>(dense.values.size() * sizeof(float)) / 1e6, dense.nx, dense.ny, dense.nz,
      densifySeconds);
  std::printf("\n%-10s %-9s %12s %12s %8s\n", "lookups", "interp", "dense ns", "sparse ns",
              "ratio");
  const std::pair<const char*, Interpolation> interps[] = {{"nearest", Interpolation::Nearest},
                                                           {"trilinear", Interpolation::Trilinear},
                                                           {"tricubic", Interpolation::Tricubic}};
  for (bool random : {false, true}) {
    const std::vector<Vec3> points = lookupPoints(g, random);
    for (const auto& [name, interp] : interps) {
      double a = 0.0, b = 0.0;
      const auto [dn, sn] = nanosPerLookup(
          points, [&](const Vec3& p) { return dense.sample(p, interp); },
          [&](const Vec3& p) { return g.sampleIndex(p, interp); }, a, b);
      std::printf("%-10s %-9s %12.1f %12.1f %8.2f%s\n", random ? "random" : "along rays", name, dn,
                  sn, sn / dn,
                  std::abs(a - b) <= 1e-6 * std::abs(a) + 1e-3 ? "" : "  (values differ!)");
    }
  }
  // Majorant walks: nanoseconds per visited cell, per level, over rays through the grid.
  std::printf("\n%-8s %12s %14s %16s\n", "walk", "cells/ray", "ns per cell", "majorant depth");
  const Bounds3 w = g.worldBounds();
  Rng rng(13, 14);
  std::vector<Ray> rays(20000);
  for (Ray& r : rays) {
    const Vec3 from =
        w.center() + uniformSphere(rng.uniform(), rng.uniform()) * length(w.diagonal());
    const Vec3 to = w.lo + mul(w.diagonal(), Vec3(rng.uniform(), rng.uniform(), rng.uniform()));
    r.origin = from;
    r.dir = normalize(to - from);
  }
  const std::pair<const char*, MajorantLevel> levels[] = {{"8^3", MajorantLevel::kBlock},
                                                          {"64^3", MajorantLevel::kNode},
                                                          {"global", MajorantLevel::kGlobal}};
  std::vector<MajorantSpan> spans;
  for (const auto& [name, level] : levels) {
    uint64_t cells = 0;
    double depth = 0.0;
    start = std::chrono::steady_clock::now();
    for (const Ray& r : rays) {
      spans.clear();
      g.majorantSpans(r, 0.0f, kInf, level, spans, &cells);
      for (const MajorantSpan& s : spans) depth += static_cast<double>(s.majorant) * (s.t1 - s.t0);
    }
    const double ns = seconds(start) * 1e9;
    std::printf("%-8s %12.1f %14.1f %16.2f\n", name,
                static_cast<double>(cells) / static_cast<double>(rays.size()),
                ns / static_cast<double>(cells), depth / static_cast<double>(rays.size()));
  }
  std::printf("\ncheapest level (trilinear):");
  for (float scale : {0.001f, 0.01f, 0.08f, 1.0f, 10.0f}) {
    const MajorantLevel level = g.cheapestMajorantLevel(scale, Interpolation::Trilinear);
    std::printf("  scale %g: %s", static_cast<double>(scale),
                level == MajorantLevel::kBlock  ? "8^3"
                : level == MajorantLevel::kNode ? "64^3"
                                                : "global");
  }
  std::printf("\n");
  return 0;
}

}  // namespace
}  // namespace lvox

int main(int argc, char** argv) {
  const std::string file =
      argc > 1 ? argv[1]
               : std::string(LVOX_SOURCE_DIR) + "/../shared/assets/vdb/wdas_cloud_sixteenth.vdb";
  const std::string grid = argc > 2 ? argv[2] : "density";
  try {
    return lvox::run(file, grid);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lvox_sparse_lookups: %s\n", e.what());
    return 1;
  }
}
