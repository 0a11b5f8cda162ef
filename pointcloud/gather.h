#pragma once
// Gathers (phase 2): rays cast into the point cloud from a surface point (cosine-weighted
// hemisphere) or a point in a medium (sphere weighted by the phase function).
//
// Units. A surfel caches its outgoing radiance L_s = albedo * E_direct / pi [W/(m^2 sr)];
// a gather ray that reaches it unoccluded returns L_s times the transmittance of the
// lvoxels in front. An lvoxel crossed over a chord l adds T * J * (1 - exp(-sigma_t l))
// with J = sigma_s / sigma_t * L_scatter its source radiance, then T *= exp(-sigma_t l)
// (the exact RTE solution across a homogeneous cube).
#include <cstdint>

#include "pointcloud/traversal.h"
#include "src/core/rng.h"
#include "src/core/sampling.h"

namespace lvox {

struct GatherOptions {
  int samples = 128;                 // rays per gather, stratified
  float maxSolidAngle = 0.0f;        // cluster criterion (TraversalOptions); 0 = exact
  float maxLvoxelSolidAngle = 0.0f;  // the same for lvoxel-only nodes
  float rayOffset = 1e-4f;           // ray tmin, scene units: skips the receiver's own disks
  RGB background{0, 0, 0};           // radiance of rays that leave the cloud
  float minTransmittance = 1e-4f;
};

// Radiance arriving at ray.origin from direction -ray.dir through the point cloud.
struct GatherRayVisitor {
  const PointCloud& cloud;
  float minTransmittance = 1e-4f;
  RGB radiance{0, 0, 0};
  RGB transmittance{1, 1, 1};
  bool opaqueHit = false;

  void surfel(uint32_t i, float, bool front) {
    const SurfelSet& s = cloud.surfels();
    radiance += transmittance * (front ? s.radianceFront[i] : s.radianceBack[i]);
    opaqueHit = true;
  }
  bool surfelCluster(uint32_t n, float, bool front, float coverage) {
    const SurfelCluster& c = cloud.surfelClusters()[n];
    radiance += transmittance * coverage * (front ? c.radianceFront : c.radianceBack);
    transmittance *= 1.0f - coverage;
    return maxComponent(transmittance) >= minTransmittance;
  }
  bool lvoxel(uint32_t i, float t0, float t1) {
    const LvoxelSet& l = cloud.lvoxels();
    return attenuate(l.sigmaT(i), l.sourceRadiance(i), t1 - t0);
  }
  bool lvoxelCluster(uint32_t n, float t0, float t1) {
    const LvoxelCluster& c = cloud.lvoxelClusters()[n];
    return attenuate(c.sigmaT, c.sourceRadiance, t1 - t0);
  }
  bool attenuate(const RGB& sigmaT, const RGB& source, float chord) {
    if (!(chord > 0.0f)) return true;
    const RGB tr = exp(-sigmaT * chord);
    radiance += transmittance * source * (RGB(1.0f) - tr);
    transmittance *= tr;
    return maxComponent(transmittance) >= minTransmittance;
  }
};

// One gather ray: its radiance (background added behind unoccluded media).
RGB gatherRay(const PointCloud& cloud, const Ray& ray, const GatherOptions& options,
              TraversalScratch& scratch);

// rows x cols strata with rows * cols == n exactly (rows = largest divisor <= sqrt(n)).
void strataGrid(int n, int& rows, int& cols);

// Irradiance E [W/m^2] at p with unit normal n: E = pi / N * sum L_i over N stratified
// cosine-weighted directions. Outgoing Lambertian radiance is albedo * E / pi.
RGB gatherIrradiance(const PointCloud& cloud, const Vec3& p, const Vec3& n,
                     const GatherOptions& options, Rng& rng, TraversalScratch& scratch);
RGB gatherIrradiance(const PointCloud& cloud, const Vec3& p, const Vec3& n,
                     const GatherOptions& options, Rng& rng);

// In-scattered radiance L_scatter(p, wo) = integral over the sphere of
// phase(wo, wi) L(p <- wi) dwi [W/(m^2 sr)]; the medium's source is sigma_s * L_scatter.
// Directions are stratified uniform on the sphere and weighted by phase / pdf, which
// works for any phase function (noisy for strongly peaked ones). `phase(wo, wi)` gets
// wo pointing from p to the viewer and wi pointing from p to where the light comes from.
template <class Phase>
RGB gatherInScatter(const PointCloud& cloud, const Vec3& p, const Vec3& wo, const Phase& phase,
                    const GatherOptions& options, Rng& rng, TraversalScratch& scratch) {
  int rows, cols;
  strataGrid(options.samples, rows, cols);
  RGB sum(0.0f);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const float u1 = (static_cast<float>(r) + rng.uniform()) / static_cast<float>(rows);
      const float u2 = (static_cast<float>(c) + rng.uniform()) / static_cast<float>(cols);
      const Vec3 wi = uniformSphere(u1, u2);
      const float weight = static_cast<float>(phase(wo, wi)) / kUniformSpherePdf;
      if (!(weight > 0.0f)) continue;
      Ray ray{p, wi, 0.0f, kInf};
      sum += gatherRay(cloud, ray, options, scratch) * weight;
    }
  return sum / static_cast<float>(rows * cols);
}

template <class Phase>
RGB gatherInScatter(const PointCloud& cloud, const Vec3& p, const Vec3& wo, const Phase& phase,
                    const GatherOptions& options, Rng& rng) {
  TraversalScratch scratch;
  return gatherInScatter(cloud, p, wo, phase, options, rng, scratch);
}

struct IsotropicPhase {
  float operator()(const Vec3&, const Vec3&) const { return 1.0f / (4.0f * kPi); }
};

}  // namespace lvox
