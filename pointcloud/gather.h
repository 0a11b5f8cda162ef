#pragma once
// Gathers (phase 2): rays cast into the point cloud from a surface point (cosine-weighted
// hemisphere) or a point in a medium (sphere weighted by the phase function).
//
// Units. A surfel caches its outgoing radiance L_s = albedo * E_direct / pi [W/(m^2 sr)];
// a gather ray that reaches it unoccluded returns L_s times the transmittance of the
// lvoxels in front. An lvoxel crossed over a chord l adds T * J * (1 - exp(-sigma_t l))
// with J = sigma_s / sigma_t * L_scatter its source radiance, then T *= exp(-sigma_t l)
// (the exact RTE solution across a homogeneous cube).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <type_traits>

#include "pointcloud/gather_light_cells.h"
#include "pointcloud/own_cube.h"
#include "pointcloud/surfel_lookup.h"
#include "pointcloud/traversal.h"
#include "pointcloud/triangle_surfel_lattice.h"
#include "src/core/low_discrepancy.h"
#include "src/core/rng.h"
#include "src/core/sampling.h"
#include "src/geometry/ray_tracer.h"

namespace lvox {

// The light a traced gather hit reflects straight from the point, spot and directional
// lights, evaluated at the hit itself (the renderer's shadow rays). A cloud whose surfels
// leave these lights out caches only the smooth rest of their light: a delta light's
// shadow edges and its dependence on the surface's orientation are sharper than the
// surfel spacing, and the nearest surfel to a hit stood for them several per cent too
// dark on Sponza (docs/pcb.md). One virtual call per gather ray that hits a surface.
class SurfaceHitLight {
 public:
  virtual ~SurfaceHitLight() = default;
  // Radiance leaving a traced hit towards the ray's origin (hit.normal faces it).
  virtual RGB reflected(const SurfaceHit& hit) const = 0;
  // The same for a surfel's side: at p, facing n, of albedo `albedo` (cloud exports).
  virtual RGB reflected(const Vec3& p, const Vec3& n, const RGB& albedo) const = 0;
};

// Interleaved sampling between gathers: a gather's cosine rays take points [first, first +
// rays) of the Owen-scrambled (0,2)-sequence with scramble (seedU, seedV)
// (low_discrepancy.h). Gathers that take consecutive aligned ranges of one scramble cover
// the hemisphere between them as evenly as one gather with all their rays, while each
// alone is stratified as its own rays' jittered grid is: where neighbouring receivers see
// nearly the same light, their errors cancel in the average a final gather takes of them.
struct SharedStrata {
  uint32_t first = 0;
  uint32_t seedU = 0, seedV = 0;
};

struct GatherOptions {
  int samples = 128;                 // rays per gather, stratified
  float maxSolidAngle = 0.0f;        // cluster criterion (TraversalOptions); 0 = exact
  float maxLvoxelSolidAngle = 0.0f;  // the same for lvoxel-only nodes
  float rayOffset = 1e-4f;           // ray tmin, scene units: skips the receiver's own disks
  RGB background{0, 0, 0};           // radiance of rays that leave the cloud
  float minTransmittance = 1e-4f;
  // Visibility by ray tracing (`tracer` and `lattice` or `lookup` set): a gather ray finds
  // its surface with `tracer` and takes the radiance of the surfel that stands for the hit:
  // the triangle lattice's where it is set, else the lookup's exact search; the octree only
  // adds the lvoxels in front; `rayOffset` is then replaced by a few tracer epsilons.
  // Unset: the first surfel disk the traversal meets (Gibson).
  const RayTracer* tracer = nullptr;
  const TriangleSurfelLattice* lattice = nullptr;
  const SurfelLookup* lookup = nullptr;
  // With traced visibility: the delta lights' light at each hit, which the surfels then
  // do not carry (null: the surfels carry every light).
  const SurfaceHitLight* hitLight = nullptr;
  // In-scatter gathers (gatherInScatterInto) only: the part of every ray within
  // `nearReach` of its origin is sampled by `nearSamples` rays, the rest by `samples`
  // (docs/pcb.md, "The near field"). No split when nearSamples <= samples or nearReach 0.
  int nearSamples = 0;
  float nearReach = 0.0f;
  // Isotropic in-scatter gathers at an lvoxel's centre: that lvoxel. Where no surface cuts
  // its cube, the rays leave the cube out and 14 fixed directions carry its exact weights
  // (own_cube.h); -1: the rays sample it like every other cube.
  long ownLvoxel = -1;
  // cacheInterreflection only: every lvoxel's gather sets ownLvoxel to itself, except
  // where its cell holds other media's lvoxels too.
  bool ownCubeQuadrature = false;
  // Irradiance gathers only: -1, or which quarter (bit 0: u1's half, bit 1: u2's) of each
  // stratum its sample falls in, so that four gathers with the four quarters stratify
  // their directions four times as finely together (interleaved sampling).
  int quarter = -1;
  // Irradiance gathers only, in place of `quarter`: the cosine rays' directions come from
  // one Owen-scrambled (0,2)-sequence shared with neighbouring gathers (SharedStrata).
  std::optional<SharedStrata> strata;
  // Irradiance gathers with traced visibility only: `lightSamples` of the `samples` rays
  // aim at points of the lit surfaces, drawn for each receiver, the others are cosine
  // rays, and both weigh what they reach by the balance heuristic (gather_light_cells.h).
  const GatherLightCells* lights = nullptr;
  int lightSamples = 0;

  bool tracesSurfaces() const { return tracer && (lattice || lookup); }
  long surfelAt(const SurfaceHit& hit) const {
    return lattice ? lattice->nearest(hit) : lookup->nearest(hit.point, hit.normal);
  }
};

// A gather ray's near field: what it meets before `end` counts `share` of its weight (the
// ray is one of 1 / share that sample the near field), what lies beyond counts all of it.
struct NearField {
  float end = kInf;
  float share = 1.0f;
};

// Follows one gather ray through the elements the traversal visits and hands the sink
// each element's weight: the fraction of the element's radiance that arrives at the
// ray's origin (times the ray's quadrature weight `scale`). The weights depend on the
// geometry and the media only, never on the cached light, so a gather is linear in the
// cloud's radiance (GatherOperator records them once for all interreflection passes).
// Sink interface:
//   beginRay(dir) (each ray's direction, before its weights: lvoxels in anisotropic
//   media and surfel clusters send their light by direction), surfel(i, front, w),
//   surfaceLight(radiance) (weighted light from GatherOptions::hitLight),
//   surfelCluster(node, w) (w: the coverage's share; the cluster's radiance along the ray
//   is the sink's to evaluate), lvoxel(i, w), lvoxelCluster(cluster, w), addBackground(w)
template <class Sink>
struct GatherRayWeights {
  const PointCloud& cloud;
  Sink& sink;
  float scale = 1.0f;
  float minTransmittance = 1e-4f;
  NearField near;
  RGB transmittance{1, 1, 1};
  bool opaqueHit = false;
  long own = -1;  // an lvoxel whose weights come from elsewhere: it attenuates, unrecorded
  // With traced gathers: the ray, and the tracer that tells on which side of a surface
  // that cuts an lvoxel's cube (LvoxelSet::cut) the ray crosses it.
  const RayTracer* tracer = nullptr;
  Vec3 origin{0, 0, 0}, direction{0, 0, 1};

  // The ray's weight at distance t.
  float scaleAt(float t) const { return t < near.end ? scale * near.share : scale; }
  // `share`: the surface's multiple importance weight (1 without one).
  void surfel(uint32_t i, float t, bool front, float share = 1.0f) {
    sink.surfel(i, front, transmittance * (scaleAt(t) * share));
    opaqueHit = true;
  }
  bool surfelCluster(uint32_t n, float t, float coverage) {
    sink.surfelCluster(n, transmittance * (coverage * scaleAt(t)));
    transmittance *= 1.0f - coverage;
    return maxComponent(transmittance) >= minTransmittance;
  }
  bool lvoxel(uint32_t i, float t0, float t1) {
    const RGB w = attenuate(cloud.lvoxels().sigmaT(i), t0, t1);
    if (static_cast<long>(i) != own && !acrossItsSurface(i, t0, t1)) sink.lvoxel(i, w);
    return maxComponent(transmittance) >= minTransmittance;
  }
  // Whether the chord [t0, t1] of a cut lvoxel lies on the other side of the surface from
  // the cube's centre, where its light was found: that light is not the light there (a
  // cube that a wall cuts would carry the light outside the wall into the room). The
  // medium still attenuates the ray.
  bool acrossItsSurface(uint32_t i, float t0, float t1) const {
    const std::vector<uint8_t>& cut = cloud.lvoxels().cut;
    if (!tracer || cut.empty() || !cut[i]) return false;
    return tracer->blocked(origin + direction * (0.5f * (t0 + t1)), cloud.lvoxels().position[i]);
  }
  bool lvoxelCluster(uint32_t n, float t0, float t1) {
    const RGB w = attenuate(cloud.lvoxelClusters()[n].sigmaT, t0, t1);
    sink.lvoxelCluster(n, w);
    return maxComponent(transmittance) >= minTransmittance;
  }
  // A homogeneous cube crossed from t0 to t1 sends T (1 - exp(-sigma_t chord)) of its
  // source radiance; then T *= exp(-sigma_t chord). A chord across the near field's end
  // is split there, each part with its own weight.
  RGB attenuate(const RGB& sigmaT, float t0, float t1) {
    if (t0 < near.end && near.end < t1) {
      // In this order: the far part is seen through the near one.
      const RGB before = attenuateChord(sigmaT, near.end - t0, scale * near.share);
      return before + attenuateChord(sigmaT, t1 - near.end, scale);
    }
    return attenuateChord(sigmaT, t1 - t0, scaleAt(t0));
  }
  RGB attenuateChord(const RGB& sigmaT, float chord, float weight) {
    if (!(chord > 0.0f)) return RGB(0.0f);
    // Grey media (smoke, most clouds) need one exponential, not three: the same bits.
    const RGB tr = sigmaT.x == sigmaT.y && sigmaT.y == sigmaT.z ? RGB(std::exp(-sigmaT.x * chord))
                                                                : exp(-sigmaT * chord);
    const RGB w = transmittance * (RGB(1.0f) - tr) * weight;
    transmittance *= tr;
    return w;
  }
};

// Sums the weighted radiance of the cloud as it stands: the gather's radiance.
struct RadianceSink {
  const PointCloud& cloud;
  RGB background{0, 0, 0};
  RGB radiance{0, 0, 0};
  RGB escaped{0, 0, 0};  // summed weights of the rays that left the cloud (x background)
  int coefficients = cloud.lvoxels().light.coefficients();
  float yhat[kShCoefficients] = {1.0f};  // the ray's spherical harmonics (directional lvoxels)
  Vec3 direction{0, 0, 1};

  void beginRay(const Vec3& dir) {
    direction = dir;
    if (coefficients > 1) shBasis(dir, coefficients, yhat);
  }
  void surfel(uint32_t i, bool front, const RGB& w) {
    const CloudSurfels& s = cloud.surfels();
    radiance += w * (front ? s.radianceFront[i] : s.radianceBack[i]);
  }
  void surfelCluster(uint32_t n, const RGB& w) {
    radiance += w * cloud.surfelClusters()[n].radiance(direction);
  }
  void lvoxel(uint32_t i, const RGB& w) {
    radiance += w * (coefficients > 1 ? cloud.lvoxels().sourceRadiance(i, yhat)
                                      : cloud.lvoxels().sourceRadiance(i));
  }
  void lvoxelCluster(uint32_t n, const RGB& w) {
    radiance += w * shDot(cloud.lvoxelClusterCoefficients(n), yhat, coefficients);
  }
  void addBackground(const RGB& w) {
    radiance += w * background;
    escaped += w;
  }
  void surfaceLight(const RGB& weighted) { radiance += weighted; }
};

// Passes on a gather ray's surface light alone (the light a gather's rays at the lit cells
// estimate): the media in front only attenuate it, and a ray that leaves adds nothing.
template <class Sink>
struct SurfaceLightSink {
  static constexpr bool kSurfaceOnly = true;
  Sink& sink;
  void beginRay(const Vec3& dir) { sink.beginRay(dir); }
  void surfel(uint32_t i, bool front, const RGB& w) { sink.surfel(i, front, w); }
  void surfaceLight(const RGB& weighted) { sink.surfaceLight(weighted); }
  void surfelCluster(uint32_t, const RGB&) {}
  void lvoxel(uint32_t, const RGB&) {}
  void lvoxelCluster(uint32_t, const RGB&) {}
  void addBackground(const RGB&) {}
};

template <class Sink>
constexpr bool surfaceOnly() {
  if constexpr (requires { Sink::kSurfaceOnly; }) return Sink::kSurfaceOnly;
  return false;
}

// The surface's share of a gather ray's weight: all of it.
struct WholeSurface {
  float operator()(const Ray&, const SurfaceHit&) const { return 1.0f; }
};

// Where a traced gather ray starts. Off a receiver's surface (irradiance gathers): the
// origin is lifted along the normal (liftedOrigin) and every surface beyond it counts,
// however close. Until stop 51 those rays started on the surface and skipped a few
// epsilons along the ray, which let a receiver within that of an adjoining surface see
// through it: a lattice row of surfels 4e-5 above a floor, along a wall's foot, saw the
// sky below it with every ray aimed down. In a medium (lvoxel gathers, single rays):
// surfaces within a few epsilons of the origin are skipped.
enum class RayStart { kInMedium, kOffSurface };

// The lift: the shadow rays' (RenderContext::spawn) four times over.
inline Vec3 liftedOrigin(const Vec3& p, const Vec3& n, const GatherOptions& options) {
  return options.tracesSurfaces() ? p + n * (4.0f * options.tracer->epsilon()) : p;
}

// One gather ray, weighted by `scale`, into the sink; the background is added behind
// unoccluded media. With traced visibility the surface it reaches counts `share(ray, hit)`
// of that weight (a multiple importance weight); a sink of the surface's light alone skips
// the media of a ray whose surface counts nothing.
template <class Sink, class Share = WholeSurface>
void traceGatherRay(const PointCloud& cloud, const Ray& ray, const GatherOptions& options,
                    float scale, TraversalScratch& scratch, Sink& sink, NearField near = {},
                    long own = -1, const Share& share = {}, RayStart start = RayStart::kInMedium) {
  sink.beginRay(ray.dir);
  GatherRayWeights<Sink> weights{cloud, sink, scale, options.minTransmittance, near};
  weights.own = own;
  if (!options.tracesSurfaces()) {
    traverse(cloud, ray, weights,
             TraversalOptions{options.maxSolidAngle, options.maxLvoxelSolidAngle}, scratch);
  } else {
    weights.tracer = options.tracer;
    weights.origin = ray.origin;
    weights.direction = ray.dir;
    Ray traced = ray;
    traced.tmin = start == RayStart::kOffSurface ? 0.0f : 4.0f * options.tracer->epsilon();
    SurfaceHit hit;
    const bool hitSurface = options.tracer->intersect(traced, hit);
    const float surfaceShare = hitSurface ? share(ray, hit) : 0.0f;
    if constexpr (surfaceOnly<Sink>()) {
      if (!(surfaceShare > 0.0f)) return;  // occluded: nothing of the media counts either
    }
    traced.tmax = hitSurface ? hit.t : ray.tmax;
    // The epsilons are the surface's: a ray that starts inside a medium (an lvoxel's
    // gather) meets the lvoxels from its own start, else it would miss a sliver of its own
    // cube, 4 epsilons long, and see its neighbours through less of it.
    Ray media = traced;
    media.tmin = std::min(ray.tmin, traced.tmin);
    traverse(cloud, media, weights,
             TraversalOptions{options.maxSolidAngle, options.maxLvoxelSolidAngle, false}, scratch);
    if (hitSurface) {
      weights.opaqueHit = true;
      if (surfaceShare > 0.0f && maxComponent(weights.transmittance) >= options.minTransmittance) {
        if (options.hitLight)
          sink.surfaceLight(weights.transmittance * (weights.scaleAt(hit.t) * surfaceShare) *
                            options.hitLight->reflected(hit));
        const long surfel = options.surfelAt(hit);
        if (surfel >= 0) {
          const auto i = static_cast<uint32_t>(surfel);
          weights.surfel(i, hit.t, dot(cloud.surfels().normal(i), ray.dir) < 0.0f, surfaceShare);
        }
      }
    }
  }
  // A ray cut short (a near-field ray) has not left the cloud.
  if (!weights.opaqueHit && std::isinf(ray.tmax) &&
      maxComponent(weights.transmittance) >= options.minTransmittance)
    sink.addBackground(weights.transmittance * scale);
}

// One gather ray: its radiance.
RGB gatherRay(const PointCloud& cloud, const Ray& ray, const GatherOptions& options,
              TraversalScratch& scratch);

// rows x cols strata with rows * cols == n exactly (rows = largest divisor <= sqrt(n)).
void strataGrid(int n, int& rows, int& cols);

// The rays of an irradiance gather that aim at the lit cells (GatherOptions::lightSamples):
// none without traced visibility or cells, and at least one cosine ray always.
inline int lightRaysOf(const GatherOptions& options) {
  if (!options.lights || options.lights->empty() || !options.tracesSurfaces()) return 0;
  return std::clamp(options.lightSamples, 0, options.samples - 1);
}

// Directions' densities of an irradiance gather's two kinds of ray, times their counts: the
// cosine rays' n_c cos / pi and the lights' n_l q(y) d^2 / |cos_y| for the surface point y
// at distance d in that direction (solid-angle density of an area density).
struct GatherMis {
  const GatherLightCells* lights = nullptr;
  GatherLightCells::View view;  // the lights' weights for this receiver
  Vec3 normal;
  float cosineRays = 0.0f, lightRays = 0.0f;

  float lightDensity(const Ray& ray, const SurfaceHit& hit) const {
    const float q = lights->pdfArea(view, hit.triangle, hit.b1, hit.b2, -ray.dir);
    if (!(q > 0.0f)) return 0.0f;
    const float cosAtHit = std::abs(dot(hit.normal, ray.dir));
    return lightRays * q * hit.t * hit.t / std::max(cosAtHit, 1e-7f);
  }
  float cosineDensity(float cosine) const { return cosineRays * cosine * kInvPi; }
};

// A cosine ray's surface: weight n_c p_c / (n_c p_c + n_l p_l) of what the cosine rays
// alone would give it.
struct CosineRayShare {
  const GatherMis& mis;
  float operator()(const Ray& ray, const SurfaceHit& hit) const {
    const float pc = mis.cosineDensity(dot(mis.normal, ray.dir));
    return pc > 0.0f ? pc / (pc + mis.lightDensity(ray, hit)) : 0.0f;
  }
};

// A ray at a cell's point: the surface counts only where the ray reaches that point (the
// same triangle at the same distance); anything in front occludes it.
struct LightRayShare {
  uint32_t triangle;
  float distance;
  float operator()(const Ray&, const SurfaceHit& hit) const {
    return hit.triangle == triangle && std::abs(hit.t - distance) <= 1e-3f * distance ? 1.0f : 0.0f;
  }
};

// Where on the cosine map an irradiance gather's ray (r, c) of its rows x cols strata
// falls: jittered in its stratum (or in the stratum's `quarter`), or the point of the
// shared sequence (GatherOptions::strata).
inline UnitPoint2 cosineRayPoint(const GatherOptions& options, int r, int c, int rows, int cols,
                                 Rng& rng) {
  if (options.strata) {
    const SharedStrata& s = *options.strata;
    return scrambledSobol2(s.first + static_cast<uint32_t>(r * cols + c), s.seedU, s.seedV);
  }
  float j1 = rng.uniform(), j2 = rng.uniform();
  if (options.quarter >= 0) {
    j1 = 0.5f * (static_cast<float>(options.quarter & 1) + j1);
    j2 = 0.5f * (static_cast<float>((options.quarter >> 1) & 1) + j2);
  }
  return {(static_cast<float>(r) + j1) / static_cast<float>(rows),
          (static_cast<float>(c) + j2) / static_cast<float>(cols)};
}

// Irradiance E [W/m^2] at p with unit normal n: E = pi / N * sum L_i over N stratified
// cosine-weighted directions (cosine-weighted pdf cos/pi: E = integral L cos dw =
// pi * mean(L)), into the sink. Outgoing Lambertian radiance is albedo * E / pi.
// With lit cells (GatherOptions::lights) n_l of the N rays aim at points y the cells draw,
// and the surface light L_s of either kind of ray counts by the balance heuristic: the
// integral of L_s cos over the hemisphere is estimated by
//   sum over all rays of L_s cos / (n_c cos / pi + n_l q(y) d^2 / |cos_y|),
// which for a cosine ray is pi / n_c L_s times its share. The media's light along the rays
// and the background are the cosine rays' alone, as without cells.
//
// `shading`, where given, is the shading normal of a smooth-shaded surface (facing n's
// side): the cosine is its, as for the direct light and as MC's bounces take it, and a
// direction below the geometric surface n brings nothing (MC ends its path there). The
// rays still leave from just off the geometric surface.
template <class Sink>
void gatherIrradianceInto(const PointCloud& cloud, const Vec3& p, const Vec3& n,
                          const GatherOptions& options, Rng& rng, TraversalScratch& scratch,
                          Sink& sink, const Vec3* shading = nullptr) {
  const Vec3 cosineNormal = shading ? *shading : n;
  int lightRays = lightRaysOf(options);
  GatherMis mis;
  if (lightRays > 0) {
    mis.lights = options.lights;
    mis.view = options.lights->view(p, n);
    mis.normal = cosineNormal;
    if (mis.view.empty()) lightRays = 0;  // no light could reach this receiver
  }
  int rows, cols;
  strataGrid(options.samples - lightRays, rows, cols);
  const Frame frame(cosineNormal);
  // Traced rays leave from just off the surface; rays through the cloud alone from the
  // surface, past `rayOffset`.
  const Vec3 origin = liftedOrigin(p, n, options);
  const float tmin = options.tracesSurfaces() ? 0.0f : options.rayOffset;
  const float scale = kPi / static_cast<float>(rows * cols);
  mis.cosineRays = static_cast<float>(rows * cols);
  mis.lightRays = static_cast<float>(lightRays);
  const bool aimed = lightRays > 0;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const UnitPoint2 u = cosineRayPoint(options, r, c, rows, cols, rng);
      const Ray ray{origin, frame.toWorld(cosineHemisphere(u.u, u.v)), tmin, kInf};
      if (shading && !(dot(ray.dir, n) > 0.0f)) continue;
      if (aimed)
        traceGatherRay(cloud, ray, options, scale, scratch, sink, {}, -1, CosineRayShare{mis},
                       RayStart::kOffSurface);
      else
        traceGatherRay(cloud, ray, options, scale, scratch, sink, {}, -1, WholeSurface{},
                       RayStart::kOffSurface);
    }
  if (!aimed) return;
  SurfaceLightSink<Sink> surfaceLight{sink};
  for (int k = 0; k < lightRays; ++k) {  // stratified over the regions' cumulative weight
    // Not interleaved over neighbouring gathers as the cosine rays are (`quarter`): their
    // regions' weights differ, and so would the quarters' share of the regions.
    const float u1 = (static_cast<float>(k) + rng.uniform()) / static_cast<float>(lightRays);
    const float u2 = rng.uniform(), u3 = rng.uniform(), u4 = rng.uniform();
    const GatherLightCells::Sample y = options.lights->sample(mis.view, u1, u2, u3, u4);
    Vec3 dir = y.point - origin;
    const float distance = length(dir);
    if (!(distance > 0.0f) || !(y.pdfArea > 0.0f)) continue;
    dir = dir / distance;
    const float cosine = dot(cosineNormal, dir);
    const float cosAtY = -dot(y.normal, dir);  // the lit side must face the receiver
    if (!(cosine > 0.0f) || !(cosAtY > 0.0f) || !(dot(n, dir) > 0.0f)) continue;
    const float pl = static_cast<float>(lightRays) * y.pdfArea * distance * distance / cosAtY;
    const float weight = cosine / (mis.cosineDensity(cosine) + pl);
    if (!std::isfinite(weight)) continue;
    traceGatherRay(cloud, Ray{origin, dir, tmin, kInf}, options, weight, scratch, surfaceLight, {},
                   -1, LightRayShare{y.triangle, distance}, RayStart::kOffSurface);
  }
}

RGB gatherIrradiance(const PointCloud& cloud, const Vec3& p, const Vec3& n,
                     const GatherOptions& options, Rng& rng, TraversalScratch& scratch);

// The same irradiance split by where its rays ended: `background` from the rays that left
// the cloud (options.background times what the media let through), `cloud` from the rest.
struct IrradianceParts {
  RGB cloud{0.0f};
  RGB background{0.0f};
};
IrradianceParts gatherIrradianceParts(const PointCloud& cloud, const Vec3& p, const Vec3& n,
                                      const GatherOptions& options, Rng& rng,
                                      TraversalScratch& scratch, const Vec3* shading = nullptr);
RGB gatherIrradiance(const PointCloud& cloud, const Vec3& p, const Vec3& n,
                     const GatherOptions& options, Rng& rng);

// Short rays per gather ray that sample its near field alone (GatherOptions::nearSamples):
// nearSamples / samples - 1, rounded up; 0 without a near field of its own.
int nearFieldRaysPerRay(const GatherOptions& options);

struct IsotropicPhase {
  float operator()(const Vec3&, const Vec3&) const { return 1.0f / (4.0f * kPi); }
};

// In-scattered radiance L_scatter(p, wo) = integral over the sphere of
// phase(wo, wi) L(p <- wi) dwi [W/(m^2 sr)]; the medium's source is sigma_s * L_scatter.
// Directions are stratified uniform on the sphere and weighted by phase / pdf, which
// works for any phase function (noisy for strongly peaked ones). `phase(wo, wi)` gets
// wo pointing from p to the viewer and wi pointing from p to where the light comes from.
// With a near field (GatherOptions::nearSamples), each stratum also sends k short rays
// that end at nearReach, and its long ray counts 1 / (k + 1) of its weight before there:
// the integral is the same, its near part sampled by k + 1 times the rays.
template <class Phase, class Sink>
void gatherInScatterInto(const PointCloud& cloud, const Vec3& p, const Vec3& wo, const Phase& phase,
                         const GatherOptions& options, Rng& rng, TraversalScratch& scratch,
                         Sink& sink) {
  int rows, cols;
  strataGrid(options.samples, rows, cols);
  const float perRay = 1.0f / static_cast<float>(rows * cols);
  const int nearRays = nearFieldRaysPerRay(options);
  const NearField near = nearRays > 0
                             ? NearField{options.nearReach, 1.0f / static_cast<float>(nearRays + 1)}
                             : NearField{};
  auto direction = [&](int r, int c) {
    const float u1 = (static_cast<float>(r) + rng.uniform()) / static_cast<float>(rows);
    const float u2 = (static_cast<float>(c) + rng.uniform()) / static_cast<float>(cols);
    return uniformSphere(u1, u2);
  };
  // The own cube by its 14 directions where no surface cuts it (isotropic gathers only:
  // those directions are exact for band-limited light under the isotropic phase).
  long own = -1;
  if constexpr (std::is_same_v<Phase, IsotropicPhase>)
    if (options.ownLvoxel >= 0 && options.tracer &&
        !ownCubeCut(cloud.lvoxels(), static_cast<size_t>(options.ownLvoxel), p, *options.tracer))
      own = options.ownLvoxel;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const Vec3 wi = direction(r, c);
      const float weight = static_cast<float>(phase(wo, wi)) / kUniformSpherePdf;
      if (weight > 0.0f)
        traceGatherRay(cloud, Ray{p, wi, 0.0f, kInf}, options, weight * perRay, scratch, sink, near,
                       own);
      for (int k = 0; k < nearRays; ++k) {
        const Vec3 wk = direction(r, c);
        const float w = static_cast<float>(phase(wo, wk)) / kUniformSpherePdf;
        if (w > 0.0f)
          traceGatherRay(cloud, Ray{p, wk, 0.0f, options.nearReach}, options,
                         w * perRay * near.share, scratch, sink, {}, own);
      }
    }
  if (own >= 0) ownCubeInto(cloud.lvoxels(), static_cast<uint32_t>(own), sink);
}

template <class Phase>
RGB gatherInScatter(const PointCloud& cloud, const Vec3& p, const Vec3& wo, const Phase& phase,
                    const GatherOptions& options, Rng& rng, TraversalScratch& scratch) {
  RadianceSink sink{cloud, options.background};
  gatherInScatterInto(cloud, p, wo, phase, options, rng, scratch, sink);
  return sink.radiance;
}

template <class Phase>
RGB gatherInScatter(const PointCloud& cloud, const Vec3& p, const Vec3& wo, const Phase& phase,
                    const GatherOptions& options, Rng& rng) {
  TraversalScratch scratch;
  return gatherInScatter(cloud, p, wo, phase, options, rng, scratch);
}

}  // namespace lvox
