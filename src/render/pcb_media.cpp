#include "src/render/pcb_media.h"

#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "pointcloud/lvoxel_sampler.h"
#include "src/core/error.h"
#include "src/core/progress.h"
#include "src/render/cloud_exchange.h"

namespace lvox {
namespace {

constexpr float kInv4Pi = 0.25f * kInvPi;

// A medium as the lvoxel sampler sees it: the shared grid's bounds, the medium's own
// active boxes (occupied VDB blocks, or its box) and its coefficients.
struct MediumForLvoxels {
  const Medium& medium;
  Bounds3 gridBounds;
  std::vector<Bounds3> boxes;

  Bounds3 bounds() const { return gridBounds; }
  const std::vector<Bounds3>& activeBoxes() const { return boxes; }
  void coefficients(const Vec3& p, RGB& sigmaA, RGB& sigmaS) const {
    if (!medium.bounds.contains(p)) {
      sigmaA = sigmaS = RGB(0.0f);
      return;
    }
    const MediumCoefficients c = medium.at(p);
    sigmaA = c.sigmaA;
    sigmaS = c.sigmaS;
  }
  bool emits() const { return medium.emits(); }
  RGB emissionSource(const Vec3& p) const {
    return medium.bounds.contains(p) ? medium.at(p).source : RGB(0.0f);
  }
};

std::vector<Bounds3> activeBoxes(const Medium& m) {
  if (m.density) return m.density->occupiedWorldBoxes();
  return {m.bounds};
}

// Visibility x transmittance from x towards a light sample.
RGB lightTransmittance(const RenderContext& ctx, const VolumeTransport& volume, const Vec3& x,
                       const Vec3& wi, float distance, rte::SolveCounts& counts) {
  Ray shadow;
  shadow.origin = x;
  shadow.dir = wi;
  shadow.tmin = 0.0f;
  shadow.tmax = std::isinf(distance) ? kInf : distance * (1.0f - 1e-4f);
  if (ctx.tracer.occluded(shadow)) return RGB(0.0f);
  return volume.transmittance(shadow, counts);
}

}  // namespace

float lvoxelSpacing(float requested, const MediaSet& media, const std::string& sceneFile) {
  const Vec3 d = media.bounds().diagonal();
  if (!(requested > 0.0f)) return std::max({d.x, d.y, d.z}) / 48.0f;
  const float s = requested;
  // The grid covers the media's bounds; say so here, before allocating.
  const double cells = std::ceil(std::max(d.x, 0.0f) / s) * std::ceil(std::max(d.y, 0.0f) / s) *
                       std::ceil(std::max(d.z, 0.0f) / s);
  if (cells > 5e7)
    throw InputError(sceneFile, "pointcloud.lvoxel_spacing",
                     std::to_string(s) + " gives " + std::to_string(static_cast<long long>(cells)) +
                         " cells over the media (at most 50,000,000)");
  return s;
}

LvoxelSet sampleSceneLvoxels(const MediaSet& media, float spacing, int samplesPerAxis,
                             uint64_t seed, const LightSet& lights, Collective& team,
                             size_t* sampled) {
  LvoxelSettings settings;
  settings.spacing = spacing;
  settings.samplesPerAxis = samplesPerAxis;
  settings.seed = seed;
  settings.sliceIndex = team.rank();
  settings.sliceCount = team.size();
  std::vector<LvoxelSet> perMedium;
  size_t mine = 0;
  for (const Medium& m : media.media()) {
    const MediumForLvoxels adapter{m, media.bounds(), activeBoxes(m)};
    perMedium.push_back(sampleLvoxels(adapter, settings));
    mine += perMedium.back().size();
  }
  if (sampled) *sampled = mine;
  if (team.distributed()) perMedium = allgatherLvoxels(perMedium, team);
  LvoxelSet all;
  for (const LvoxelSet& part : perMedium) all.append(part);
  all.light.setChannels(lights.lights().size(), media.size());
  return all;
}

size_t cacheLvoxelDirectLight(const RenderContext& ctx, const VolumeTransport& volume,
                              LvoxelLight& light, rte::SolveCounts& counts, Collective& team) {
  const LightSet& lights = ctx.lights;
  const MediaSet& media = volume.media();
  const size_t deltaCount = lights.lights().size();
  const auto ranks = static_cast<size_t>(team.size());
  const auto rank = static_cast<size_t>(team.rank());
  auto mine = [&](size_t slot) { return (slot / kLvoxelDirectBlock) % ranks == rank; };
  tbb::combinable<rte::SolveCounts> perThread;
  Progress::global().addWork(light.occupiedCount());
  // Cells not this rank's keep the zeros setChannels and occupy gave them.
  tbb::parallel_for(size_t(0), light.occupiedCount(), [&](size_t slot) {
    Progress::global().advance(1);
    if (!mine(slot)) return;
    rte::SolveCounts& local = perThread.local();
    const Vec3 x = light.centre(static_cast<uint32_t>(slot));
    RGB* transmittance = light.transmittance(static_cast<uint32_t>(slot));
    for (size_t k = 0; k < deltaCount; ++k) {
      const LightSample s = lights.sampleDelta(lights.lights()[k], x);
      // A spot light's cone does not decide the shadowing: the centre may lie outside the
      // cone while part of the cell is inside, so the transmittance is kept regardless.
      const Light& l = lights.lights()[k];
      const Vec3 wi = l.type == LightType::Directional ? -l.direction : s.wi;
      const float distance = l.type == LightType::Directional ? kInf : length(l.position - x);
      transmittance[k] =
          distance > 0.0f ? lightTransmittance(ctx, volume, x, wi, distance, local) : RGB(1.0f);
    }
    Rng rng(ctx.settings.seed ^ 0x1f0e1u, slot);
    // Samples are weighted 1/pdf already: their sum estimates the integral of L dw, and
    // with each medium's phase towards the camera, its in-scatter along camera rays.
    const auto cell = static_cast<uint32_t>(slot);
    const Vec3 viewDir = normalize(x - ctx.world.camera.position);
    RGB isotropic(0.0f);
    RGB* towardsCamera = light.towardsCamera(cell);
    lights.forEachAreaSample(x, nullptr, rng, [&](const LightSample& s) {
      const RGB arriving = s.radiance * lightTransmittance(ctx, volume, x, s.wi, s.distance, local);
      isotropic += arriving;
      const float cosTheta = dot(s.wi, viewDir);
      for (size_t m = 0; m < media.size(); ++m)
        towardsCamera[m] += arriving * media[m].phase.eval(cosTheta);
    });
    light.areaInScatter(cell) = isotropic * kInv4Pi;
  });
  perThread.combine_each([&](const rte::SolveCounts& c) { counts += c; });
  if (team.distributed()) light.sumDirectOverRanks(team);
  size_t lit = 0;
  for (size_t slot = 0; slot < light.occupiedCount(); slot += kLvoxelDirectBlock)
    if (mine(slot)) lit += std::min(kLvoxelDirectBlock, light.occupiedCount() - slot);
  return lit;
}

RGB phaseAveragedDirect(const LightSet& lights, LvoxelLight& light, uint32_t slot) {
  const RGB* transmittance = light.transmittance(slot);
  RGB sum = light.areaInScatter(slot);
  for (size_t k = 0; k < lights.lights().size(); ++k) {
    const LightSample s = lights.sampleDelta(lights.lights()[k], light.centre(slot));
    sum += s.radiance * transmittance[k] * kInv4Pi;
  }
  return sum;
}

RGB PointCloudScatter::operator()(const Vec3& x, const Vec3& viewDir,
                                  const MediumCoefficients* perMedium) const {
  thread_local LvoxelLightSample cached;
  if (!light.interpolate(x, cached)) return RGB(0.0f);
  const size_t deltaCount = lights.lights().size();
  // Light samples of the delta lights at x: exact direction, falloff and spot profile.
  thread_local std::vector<LightSample> samples;
  samples.resize(deltaCount);
  for (size_t k = 0; k < deltaCount; ++k) samples[k] = lights.sampleDelta(lights.lights()[k], x);
  RGB source(0.0f);
  for (size_t m = 0; m < media.size(); ++m) {
    if (isBlack(perMedium[m].sigmaS)) continue;
    const PhaseFunction& phase = media[m].phase;
    RGB incident = cached.multiScatter + cached.towardsCamera[m];
    for (size_t k = 0; k < deltaCount; ++k) {
      if (isBlack(samples[k].radiance)) continue;
      incident +=
          samples[k].radiance * cached.transmittance[k] * phase.eval(dot(samples[k].wi, viewDir));
    }
    source += perMedium[m].sigmaS * incident;
  }
  return source;
}

}  // namespace lvox
