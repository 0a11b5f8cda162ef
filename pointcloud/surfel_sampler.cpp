#include "pointcloud/surfel_sampler.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <tuple>

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

float diskRadius(const UniformSurfelSettings& s) {
  return s.spacing / std::sqrt(kPi) * s.radiusScale;
}

bool usesLattice(const TriangleInfo& t, float spacing) {
  return t.area / (spacing * spacing) >= kLatticeMinSurfels;
}

// Twice the signed area of (a, b, p): > 0 when p is left of a -> b.
float edgeFunction(float ax, float ay, float bx, float by, float px, float py) {
  return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

// Closest point q to (px, py) on the segment a -> b, at parameter u in [0, 1].
void closestOnSegment(float ax, float ay, float bx, float by, float px, float py, float& qx,
                      float& qy, float& u) {
  const float dx = bx - ax, dy = by - ay;
  const float len2 = dx * dx + dy * dy;
  u = len2 > 0.0f ? std::clamp(((px - ax) * dx + (py - ay) * dy) / len2, 0.0f, 1.0f) : 0.0f;
  qx = ax + u * dx;
  qy = ay + u * dy;
}

// A lattice triangle in the 2D frame of its plane, with what its border sites need.
struct PlanarTriangle {
  float x[3], y[3];
  float orientation;    // +1 counter-clockwise, -1 clockwise
  float cx, cy;         // centroid
  uint8_t borderEdges;  // bit e: the edge from vertex e to e + 1 is a border
  float outX[3] = {0, 0, 0}, outY[3] = {0, 0, 0};  // outward unit normals of border edges

  PlanarTriangle(const TriangleInfo& t, const Frame& frame, uint8_t borders)
      : x{dot(t.v0, frame.s), dot(t.v1, frame.s), dot(t.v2, frame.s)},
        y{dot(t.v0, frame.t), dot(t.v1, frame.t), dot(t.v2, frame.t)},
        orientation(edgeFunction(x[0], y[0], x[1], y[1], x[2], y[2]) >= 0.0f ? 1.0f : -1.0f),
        cx((x[0] + x[1] + x[2]) / 3.0f),
        cy((y[0] + y[1] + y[2]) / 3.0f),
        borderEdges(borders) {
    for (int e = 0; e < 3; ++e) {
      const int f = (e + 1) % 3;
      const float len = std::hypot(x[f] - x[e], y[f] - y[e]);
      if (!isBorder(e) || !(len > 0.0f)) continue;
      outX[e] = orientation * (y[f] - y[e]) / len;
      outY[e] = -orientation * (x[f] - x[e]) / len;
    }
  }
  bool isBorder(int e) const { return (borderEdges & (1u << e)) != 0; }
  bool beyond(int e, float px, float py) const {
    const int f = (e + 1) % 3;
    return orientation * edgeFunction(x[e], y[e], x[f], y[f], px, py) < 0.0f;
  }

  // The cut of a disk centred at (px, py): along the nearest border edge closer than
  // `radius`, none if there is none.
  DiskClip clipAt(float px, float py, const Frame& frame, float radius) const {
    DiskClip clip;
    float nearest = radius;
    for (int e = 0; e < 3; ++e) {
      if (outX[e] == 0.0f && outY[e] == 0.0f) continue;
      const float inside = outX[e] * (x[e] - px) + outY[e] * (y[e] - py);
      if (inside < nearest) {
        nearest = inside;
        clip = {frame.s * outX[e] + frame.t * outY[e], std::max(inside, 0.0f)};
      }
    }
    return clip;
  }

  // A lattice site (px, py) outside the triangle, moved onto it, `inset` inside towards
  // the centroid. False when it lies beyond a shared edge (the neighbour's), farther than
  // `reach` from the triangle, or at a corner that has its site already.
  bool borderSite(float px, float py, float reach, float inset, bool cornerTaken[3], float& qx,
                  float& qy) const {
    for (int e = 0; e < 3; ++e)
      if (beyond(e, px, py) && !isBorder(e)) return false;
    float best = kInf;
    int corner = -1;
    qx = px;
    qy = py;
    for (int e = 0; e < 3; ++e) {
      const int f = (e + 1) % 3;
      float ex, ey, u;
      closestOnSegment(x[e], y[e], x[f], y[f], px, py, ex, ey, u);
      const float d2 = (ex - px) * (ex - px) + (ey - py) * (ey - py);
      if (d2 < best) {
        best = d2;
        qx = ex;
        qy = ey;
        corner = u <= 0.0f ? e : (u >= 1.0f ? f : -1);
      }
    }
    if (!(best <= reach * reach)) return false;
    if (corner >= 0) {
      if (cornerTaken[corner]) return false;
      cornerTaken[corner] = true;
    }
    const float toCentre = std::hypot(cx - qx, cy - qy);
    const float k = toCentre > 0.0f ? std::min(inset / toCentre, 1.0f) : 0.0f;
    qx += (cx - qx) * k;
    qy += (cy - qy) * k;
    return true;
  }
};

// Points of the hexagonal lattice (density 1/spacing^2) of the triangle's plane that lie
// inside the triangle. The lattice offset depends on the seed only, so coplanar
// triangles share one lattice and a quad split in two has no seam.
//
// Border edges (bit e of `borderEdges` for the edge from vertex e to e + 1: shared with
// no coplanar lattice triangle) also get the lattice sites just outside them, moved onto
// the triangle. A point of the triangle whose nearest lattice site lies outside is
// otherwise not covered when that site is farther than the disk radius: strips along the
// borders stay open and gather rays leave through them (the furnace test at coarse
// spacing, docs/pointcloud.md). Every point of the plane is within the covering radius
// R = a / sqrt(3) of a site, and moving a site onto the (convex) triangle brings it no
// farther from any point of the triangle, so with these sites every point of the
// triangle is within R < disk radius of a surfel. Sites beyond an edge shared with a
// coplanar neighbour are the neighbour's; a corner gets at most one site.
//
// A disk within its radius of a border edge is cut along that edge (DiskClip): coverage
// needs no part of it beyond the edge, and at a convex edge that part would stand in
// front of the adjoining face and show it the disk's other side.
template <class Emit>
void latticePoints(const TriangleInfo& t, float spacing, float diskRadius, uint64_t seed,
                   uint8_t borderEdges, Emit&& emit) {
  const Frame frame(canonicalNormal(t.unitNormal));
  const float a = spacing * std::sqrt(2.0f / std::sqrt(3.0f));  // hexagon cell area = s^2
  const float rowHeight = a * std::sqrt(3.0f) * 0.5f;
  const float coveringRadius = a / std::sqrt(3.0f);
  // Border sites sit this far inside the edge, so that their shadow rays do not start on
  // the plane of the adjoining surface.
  const float inset = 0.02f * spacing;
  Rng rng(seed, 0x1a771ceull);
  const float offU = rng.uniform() * a, offV = rng.uniform() * rowHeight;
  const PlanarTriangle tri(t, frame, borderEdges);
  const float w = dot(t.v0, frame.n);
  auto emitAt = [&](float px, float py) {
    emit(frame.s * px + frame.t * py + frame.n * w, tri.clipAt(px, py, frame, diskRadius));
  };
  const float margin = borderEdges != 0 ? coveringRadius : 0.0f;
  const float ylo = std::min({tri.y[0], tri.y[1], tri.y[2]}) - margin;
  const float yhi = std::max({tri.y[0], tri.y[1], tri.y[2]}) + margin;
  const float xlo = std::min({tri.x[0], tri.x[1], tri.x[2]}) - margin;
  const float xhi = std::max({tri.x[0], tri.x[1], tri.x[2]}) + margin;
  bool cornerTaken[3] = {false, false, false};
  const auto j0 = static_cast<long>(std::floor((ylo - offV) / rowHeight));
  const auto j1 = static_cast<long>(std::ceil((yhi - offV) / rowHeight));
  for (long j = j0; j <= j1; ++j) {
    const float py = offV + static_cast<float>(j) * rowHeight;
    const float rowShift = offU + ((j & 1) ? 0.5f * a : 0.0f);
    const auto i0 = static_cast<long>(std::floor((xlo - rowShift) / a));
    const auto i1 = static_cast<long>(std::ceil((xhi - rowShift) / a));
    for (long i = i0; i <= i1; ++i) {
      const float px = rowShift + static_cast<float>(i) * a;
      float qx = px, qy = py;
      if (inside2d(px, py, tri.x, tri.y))
        emitAt(px, py);
      else if (borderEdges != 0 &&
               tri.borderSite(px, py, coveringRadius, inset, cornerTaken, qx, qy))
        emitAt(qx, qy);
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
    emit(t.v0 * (1.0f - b1 - b2) + t.v1 * b1 + t.v2 * b2, DiskClip{});
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
    const TriangleInfo t = triangleInfo(mesh, i);
    if (usesLattice(t, spacing)) continue;
    const double expected = t.area * invArea;
    const double before = std::floor(cumulative + u0);
    cumulative += expected;
    counts[i] = static_cast<uint32_t>(std::floor(cumulative + u0) - before);
  }
  return counts;
}

// Per triangle, bit e set when its edge from vertex e to e + 1 is a border of the lattice
// of its plane: no other lattice triangle of the same plane shares that edge (by vertex
// positions, so unwelded meshes work too).
std::vector<uint8_t> latticeBorderEdges(const TriangleMesh& mesh, float spacing) {
  struct EdgeRecord {
    std::array<float, 6> key;  // the two end points, in lexicographic order
    uint32_t triangle;
    uint8_t edge;
  };
  const size_t n = mesh.triangleCount();
  std::vector<uint8_t> masks(n, 0);
  std::vector<EdgeRecord> records;
  records.reserve(3 * n);
  for (size_t tri = 0; tri < n; ++tri) {
    if (!usesLattice(triangleInfo(mesh, tri), spacing)) continue;
    masks[tri] = 0b111;
    for (int e = 0; e < 3; ++e) {
      Vec3 p = mesh.vertex(tri, e), q = mesh.vertex(tri, (e + 1) % 3);
      if (std::tie(q.x, q.y, q.z) < std::tie(p.x, p.y, p.z)) std::swap(p, q);
      records.push_back(
          {{p.x, p.y, p.z, q.x, q.y, q.z}, static_cast<uint32_t>(tri), static_cast<uint8_t>(e)});
    }
  }
  std::sort(records.begin(), records.end(), [](const EdgeRecord& l, const EdgeRecord& r) {
    return std::tie(l.key, l.triangle, l.edge) < std::tie(r.key, r.triangle, r.edge);
  });
  for (size_t begin = 0; begin < records.size();) {
    size_t end = begin + 1;
    while (end < records.size() && records[end].key == records[begin].key) ++end;
    for (size_t i = begin; i < end; ++i)
      for (size_t j = begin; j < end; ++j) {
        if (i == j) continue;
        const Vec3 ni = triangleInfo(mesh, records[i].triangle).unitNormal;
        const Vec3 nj = triangleInfo(mesh, records[j].triangle).unitNormal;
        // Sharing an edge, parallel normals mean one plane (either winding).
        if (std::abs(dot(ni, nj)) > 1.0f - 1e-5f)
          masks[records[i].triangle] &= static_cast<uint8_t>(~(1u << records[i].edge));
      }
    begin = end;
  }
  return masks;
}

template <class Emit>
void trianglePoints(const TriangleInfo& t, size_t tri, uint32_t smallCount, uint8_t borderEdges,
                    const UniformSurfelSettings& s, Emit&& emit) {
  if (usesLattice(t, s.spacing)) {
    latticePoints(t, s.spacing, diskRadius(s), s.seed, borderEdges, emit);
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
                               const UniformSurfelSettings& settings,
                               const SurfaceTextures* textures) {
  if (!(settings.spacing > 0.0f) || !std::isfinite(settings.spacing))
    throw InputError(kSettingsName, "surfel_spacing", "must be a positive number");
  if (!(settings.radiusScale >= 1.0f))
    throw InputError(kSettingsName, "surfel_radius_scale", "must be >= 1");
  const size_t n = mesh.triangleCount();
  const std::vector<uint32_t> smallCounts =
      smallTriangleCounts(mesh, settings.spacing, settings.seed);
  const std::vector<uint8_t> borders = latticeBorderEdges(mesh, settings.spacing);

  // Pass 1 counts each triangle's surfels, pass 2 writes them at the prefix offsets:
  // the result is independent of the thread schedule.
  // No surfel stands on a cut-away texel (both passes ask the same question).
  auto cutAway = [&](size_t tri, const Vec3& p) {
    if (!textures || !textures->hasCutout(static_cast<uint32_t>(tri))) return false;
    const Vec2 b = mesh.barycentricOf(tri, p);
    return textures->isCutAway(static_cast<uint32_t>(tri), b.x, b.y);
  };
  const size_t first = std::min(settings.firstTriangle, n);
  const size_t end = std::clamp(settings.endTriangle, first, n);
  std::vector<size_t> offsets(end - first + 1, 0);
  tbb::parallel_for(first, end, [&](size_t tri) {
    size_t c = 0;
    trianglePoints(triangleInfo(mesh, tri), tri, smallCounts[tri], borders[tri], settings,
                   [&](const Vec3& p, const DiskClip&) {
                     if (!cutAway(tri, p)) ++c;
                   });
    offsets[tri - first + 1] = c;
  });
  for (size_t i = 0; i + 1 < offsets.size(); ++i) offsets[i + 1] += offsets[i];

  SurfelSet surfels;
  surfels.radiusScale = settings.radiusScale;
  surfels.resize(offsets.back());
  const float radius = diskRadius(settings);
  tbb::parallel_for(first, end, [&](size_t tri) {
    const TriangleInfo t = triangleInfo(mesh, tri);
    const Material& material = materialOf(mesh, materials, tri);
    const bool textured = textures && material.albedoMap >= 0;
    size_t k = offsets[tri - first];
    trianglePoints(
        t, tri, smallCounts[tri], borders[tri], settings, [&](const Vec3& p, const DiskClip& clip) {
          if (cutAway(tri, p)) return;
          RGB albedo = material.albedo;
          if (textured) {
            // The albedo the surfel's disk averages, for the interreflection.
            const Vec2 b = mesh.barycentricOf(tri, p);
            albedo = textures->albedoOverDisk(static_cast<uint32_t>(tri), b.x, b.y, radius);
          }
          surfels.position[k] = p;
          surfels.clip[k] = clip;
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
  float b1, b2;
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
      rows[iy].push_back({hit.point, hit.normal, std::sqrt(area / kPi) * settings.radiusScale,
                          hit.triangle, hit.b1, hit.b2});
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
      const Material& m = materialOf(tracer.mesh(), materials, s.triangle);
      surfels.albedo[k] = m.albedoMap >= 0 && tracer.textures()
                              ? tracer.textures()->albedoOverDisk(s.triangle, s.b1, s.b2, s.radius)
                              : m.albedo;
      surfels.triangle[k] = s.triangle;
      ++k;
    }
  return surfels;
}

}  // namespace lvox
