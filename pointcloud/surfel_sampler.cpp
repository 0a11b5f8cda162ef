#include "pointcloud/surfel_sampler.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <string>

#include "src/core/error.h"
#include "src/core/rng.h"
#include "src/core/sampling.h"

namespace lvox {

namespace {

constexpr const char* kSettingsName = "pointcloud settings";

struct TriangleInfo {
  Vec3 v0, v1, v2;
  Vec3 unitNormal;
  float area = 0.0f;
};

TriangleInfo triangleInfo(const TriangleMesh& mesh, size_t tri) {
  TriangleInfo t;
  t.v0 = mesh.vertex(tri, 0);
  t.v1 = mesh.vertex(tri, 1);
  t.v2 = mesh.vertex(tri, 2);
  const Vec3 c = cross(t.v1 - t.v0, t.v2 - t.v0);
  const float len = length(c);
  t.area = 0.5f * len;
  t.unitNormal = len > 0.0f ? c / len : Vec3(0, 0, 1);
  return t;
}

// Sign-canonical normal: the two windings of one plane get the same lattice frame.
Vec3 canonicalNormal(const Vec3& n) {
  const Vec3 a(std::abs(n.x), std::abs(n.y), std::abs(n.z));
  const int axis = (a.x >= a.y && a.x >= a.z) ? 0 : (a.y >= a.z ? 1 : 2);
  return n[axis] < 0.0f ? -n : n;
}

bool inside2d(float px, float py, const float* x, const float* y) {
  float sign = 0.0f;
  for (int e = 0; e < 3; ++e) {
    const int f = (e + 1) % 3;
    const float w = (x[f] - x[e]) * (py - y[e]) - (y[f] - y[e]) * (px - x[e]);
    if (w == 0.0f) continue;
    if (sign == 0.0f) sign = w;
    if ((w > 0.0f) != (sign > 0.0f)) return false;
  }
  return true;
}

// Points of the hexagonal lattice (density 1/spacing^2) of the triangle's plane that lie
// inside the triangle. The lattice offset depends on the seed only.
template <class Emit>
void latticePoints(const TriangleInfo& t, float spacing, uint64_t seed, Emit&& emit) {
  const Frame frame(canonicalNormal(t.unitNormal));
  const float a = spacing * std::sqrt(2.0f / std::sqrt(3.0f));  // hexagon cell area = s^2
  const float rowHeight = a * std::sqrt(3.0f) * 0.5f;
  Rng rng(seed, 0x1a771ceull);
  const float offU = rng.uniform() * a, offV = rng.uniform() * rowHeight;
  const float x[3] = {dot(t.v0, frame.s), dot(t.v1, frame.s), dot(t.v2, frame.s)};
  const float y[3] = {dot(t.v0, frame.t), dot(t.v1, frame.t), dot(t.v2, frame.t)};
  const float w = dot(t.v0, frame.n);
  const float ylo = std::min({y[0], y[1], y[2]}), yhi = std::max({y[0], y[1], y[2]});
  const float xlo = std::min({x[0], x[1], x[2]}), xhi = std::max({x[0], x[1], x[2]});
  const auto j0 = static_cast<long>(std::floor((ylo - offV) / rowHeight));
  const auto j1 = static_cast<long>(std::ceil((yhi - offV) / rowHeight));
  for (long j = j0; j <= j1; ++j) {
    const float py = offV + static_cast<float>(j) * rowHeight;
    const float rowShift = offU + ((j & 1) ? 0.5f * a : 0.0f);
    const auto i0 = static_cast<long>(std::floor((xlo - rowShift) / a));
    const auto i1 = static_cast<long>(std::ceil((xhi - rowShift) / a));
    for (long i = i0; i <= i1; ++i) {
      const float px = rowShift + static_cast<float>(i) * a;
      if (inside2d(px, py, x, y)) emit(frame.s * px + frame.t * py + frame.n * w);
    }
  }
}

// `count` points stratified along the first warp dimension of the triangle.
template <class Emit>
void stratifiedPoints(const TriangleInfo& t, uint32_t count, Rng& rng, Emit&& emit) {
  for (uint32_t k = 0; k < count; ++k) {
    const float u1 = (static_cast<float>(k) + rng.uniform()) / static_cast<float>(count);
    float b1, b2;
    uniformTriangle(u1, rng.uniform(), b1, b2);
    emit(t.v0 * (1.0f - b1 - b2) + t.v1 * b1 + t.v2 * b2);
  }
}

// Surfels of triangles too small for the lattice: floor/ceil of the expected count by
// systematic rounding, so every triangle gets its fair share and the total is exact.
std::vector<uint32_t> smallTriangleCounts(const TriangleMesh& mesh, float spacing, uint64_t seed) {
  const size_t n = mesh.triangleCount();
  std::vector<uint32_t> counts(n, 0);
  Rng rng(seed, 0x5ca1ab1eull);
  const double u0 = rng.uniformDouble();
  double cumulative = 0.0;
  const double invArea = 1.0 / (static_cast<double>(spacing) * spacing);
  for (size_t i = 0; i < n; ++i) {
    const double expected = triangleInfo(mesh, i).area * invArea;
    if (expected >= kLatticeMinSurfels) continue;
    const double before = std::floor(cumulative + u0);
    cumulative += expected;
    counts[i] = static_cast<uint32_t>(std::floor(cumulative + u0) - before);
  }
  return counts;
}

template <class Emit>
void trianglePoints(const TriangleInfo& t, size_t tri, uint32_t smallCount,
                    const UniformSurfelSettings& s, Emit&& emit) {
  const float expected = t.area / (s.spacing * s.spacing);
  if (expected >= kLatticeMinSurfels) {
    latticePoints(t, s.spacing, s.seed, emit);
  } else if (smallCount > 0) {
    Rng rng(s.seed, tri);
    stratifiedPoints(t, smallCount, rng, emit);
  }
}

const Material& materialOf(const TriangleMesh& mesh, const std::vector<Material>& materials,
                           size_t tri) {
  const uint32_t m = mesh.triangleMaterial[tri];
  if (m >= materials.size())
    throw InputError(kSettingsName, "materials",
                     "triangle " + std::to_string(tri) + " has no material " + std::to_string(m));
  return materials[m];
}

}  // namespace

SurfelSet sampleSurfelsUniform(const TriangleMesh& mesh, const std::vector<Material>& materials,
                               const UniformSurfelSettings& settings) {
  if (!(settings.spacing > 0.0f) || !std::isfinite(settings.spacing))
    throw InputError(kSettingsName, "surfel_spacing", "must be a positive number");
  if (!(settings.radiusScale >= 1.0f))
    throw InputError(kSettingsName, "surfel_radius_scale", "must be >= 1");
  const size_t n = mesh.triangleCount();
  const std::vector<uint32_t> smallCounts =
      smallTriangleCounts(mesh, settings.spacing, settings.seed);

  // Pass 1 counts each triangle's surfels, pass 2 writes them at the prefix offsets:
  // the result is independent of the thread schedule.
  std::vector<size_t> offsets(n + 1, 0);
  tbb::parallel_for(size_t(0), n, [&](size_t tri) {
    size_t c = 0;
    trianglePoints(triangleInfo(mesh, tri), tri, smallCounts[tri], settings,
                   [&](const Vec3&) { ++c; });
    offsets[tri + 1] = c;
  });
  for (size_t i = 0; i < n; ++i) offsets[i + 1] += offsets[i];

  SurfelSet surfels;
  surfels.radiusScale = settings.radiusScale;
  surfels.resize(offsets[n]);
  const float radius = settings.spacing / std::sqrt(kPi) * settings.radiusScale;
  tbb::parallel_for(size_t(0), n, [&](size_t tri) {
    const TriangleInfo t = triangleInfo(mesh, tri);
    const RGB albedo = materialOf(mesh, materials, tri).albedo;
    size_t k = offsets[tri];
    trianglePoints(t, tri, smallCounts[tri], settings, [&](const Vec3& p) {
      surfels.position[k] = p;
      surfels.normal[k] = t.unitNormal;
      surfels.radius[k] = radius;
      surfels.albedo[k] = albedo;
      surfels.triangle[k] = static_cast<uint32_t>(tri);
      ++k;
    });
  });
  return surfels;
}

namespace {

struct CameraSample {
  Vec3 position, normal;
  float radius;
  uint32_t triangle;
};

}  // namespace

SurfelSet sampleSurfelsFromCamera(const RayTracer& tracer, const std::vector<Material>& materials,
                                  const Camera& camera, const CameraSurfelSettings& settings) {
  if (!(settings.rate > 0.0f) || !std::isfinite(settings.rate))
    throw InputError(kSettingsName, "surfel_rate", "must be a positive number");
  if (!(settings.margin >= 0.0f) || !(settings.margin < 10.0f))
    throw InputError(kSettingsName, "surfel_margin", "must be in [0, 10)");
  if (camera.width <= 0 || camera.height <= 0)
    throw InputError(kSettingsName, "camera", "image size must be positive");
  const float w = static_cast<float>(camera.width), h = static_cast<float>(camera.height);
  const auto nx = static_cast<size_t>(std::ceil(w * settings.rate * (1.0f + settings.margin)));
  const auto ny = static_cast<size_t>(std::ceil(h * settings.rate * (1.0f + settings.margin)));
  const float step = 1.0f / settings.rate;  // pixels between rays
  const float x0 = -0.5f * settings.margin * w, y0 = -0.5f * settings.margin * h;
  const Vec3 forward = normalize(camera.lookAt - camera.position);
  const float tanHalf = std::tan(0.5f * camera.vfovDeg * kPi / 180.0f);
  const float side = 2.0f * tanHalf / h * step;  // ray spacing on the plane at distance 1
  const float minCos = std::clamp(settings.minCosine, 1e-3f, 1.0f);

  std::vector<std::vector<CameraSample>> rows(ny);
  tbb::parallel_for(size_t(0), ny, [&](size_t iy) {
    Rng rng(settings.seed, iy);
    for (size_t ix = 0; ix < nx; ++ix) {
      const float px = x0 + (static_cast<float>(ix) + rng.uniform()) * step;
      const float py = y0 + (static_cast<float>(iy) + rng.uniform()) * step;
      const Ray ray = camera.generateRay(px, py);
      SurfaceHit hit;
      if (!tracer.intersect(ray, hit)) continue;
      const float cosAxis = dot(ray.dir, forward);
      const float solidAngle = side * side * cosAxis * cosAxis * cosAxis;
      const float cosSurface = std::max(std::abs(dot(ray.dir, hit.normal)), minCos);
      const float area = solidAngle * hit.t * hit.t / cosSurface;
      rows[iy].push_back(
          {hit.point, hit.normal, std::sqrt(area / kPi) * settings.radiusScale, hit.triangle});
    }
  });

  size_t total = 0;
  for (const auto& r : rows) total += r.size();
  SurfelSet surfels;
  surfels.radiusScale = settings.radiusScale;
  surfels.resize(total);
  size_t k = 0;
  for (const auto& r : rows)
    for (const CameraSample& s : r) {
      surfels.position[k] = s.position;
      surfels.normal[k] = s.normal;
      surfels.radius[k] = s.radius;
      surfels.albedo[k] = materialOf(tracer.mesh(), materials, s.triangle).albedo;
      surfels.triangle[k] = s.triangle;
      ++k;
    }
  return surfels;
}

}  // namespace lvox
