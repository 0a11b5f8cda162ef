#include "src/render/pcb_media.h"

#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "pointcloud/cube_transmittance.h"
#include "pointcloud/lvoxel_sampler.h"
#include "pointcloud/own_cube.h"
#include "src/core/error.h"
#include "src/core/progress.h"
#include "src/core/spherical_harmonics.h"
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

// The path from x towards a light sample: whether a surface blocks it, and if not the
// media's transmittance along it (`reduced`: without the media's forward peaks,
// VolumeTransport::transmittance).
struct LightPath {
  bool visible = false;
  RGB transmittance{0.0f};
  RGB clear() const { return RGB(visible ? 1.0f : 0.0f); }
};

LightPath lightPath(const RenderContext& ctx, const VolumeTransport& volume, const Vec3& x,
                    const Vec3& wi, float distance, bool reduced, rte::SolveCounts& counts) {
  const Ray shadow = shadowRayFrom(x, wi, distance);
  if (ctx.tracer.occluded(shadow)) return {};
  return {true, volume.transmittance(shadow, counts, reduced)};
}

// The same path through the lvoxels' cubes (cube_transmittance.h), which hold the reduced
// medium where the lvoxels are directional.
LightPath cubePath(const RenderContext& ctx, const PointCloud& cubes, const Vec3& x, const Vec3& wi,
                   float distance) {
  const Ray shadow = shadowRayFrom(x, wi, distance);
  if (ctx.tracer.occluded(shadow)) return {};
  thread_local TraversalScratch scratch;
  return {true, cubeTransmittance(cubes, shadow, scratch)};
}

// Anisotropic media give the cloud directional lvoxels (delta-M, docs/pcb.md): each keeps
// the moments of its phase without the forward peak, and its sigma_s loses the peak's
// share f. The cloud's light then carries nine coefficients per colour.
void reduceForwardPeaks(const MediaSet& media, std::vector<LvoxelSet>& perMedium) {
  for (size_t m = 0; m < perMedium.size(); ++m) {
    const PhaseFunction::Truncated t = media[m].phase.truncated(kShBands);
    LvoxelSet& l = perMedium[m];
    std::array<float, kShBands - 1> moments;
    for (int b = 1; b < kShBands; ++b) moments[static_cast<size_t>(b - 1)] = t.moment[b];
    l.phaseMoments.assign(l.size(), moments);
    for (RGB& sigmaS : l.sigmaS) sigmaS *= 1.0f - t.forward;
  }
}

}  // namespace

bool anisotropicLvoxels(const MediaSet& media) {
  for (const Medium& m : media.media())
    if (m.phase.moment(1) != 0.0f) return true;
  return false;
}

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
                             LvoxelExtinction extinction, uint64_t seed, const LightSet& lights,
                             bool directional, Collective& team, size_t* sampled) {
  LvoxelSettings settings;
  settings.spacing = spacing;
  settings.samplesPerAxis = samplesPerAxis;
  settings.keepTransmittance = extinction == LvoxelExtinction::kTransmittance;
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
  if (directional) reduceForwardPeaks(media, perMedium);
  LvoxelSet all;
  for (const LvoxelSet& part : perMedium) all.append(part);
  all.light.setChannels(lights.lights().size(), media.size());
  if (directional) all.light.setCoefficients(kShCoefficients);
  return all;
}

size_t cacheLvoxelDirectLight(const RenderContext& ctx, const VolumeTransport& volume,
                              LvoxelLight& light, rte::SolveCounts& counts, Collective& team,
                              const PointCloud* skyCubes) {
  const LightSet& lights = ctx.lights;
  const MediaSet& media = volume.media();
  const size_t deltaCount = lights.lights().size();
  const auto ranks = static_cast<size_t>(team.size());
  const auto rank = static_cast<size_t>(team.rank());
  auto mine = [&](size_t slot) { return (slot / kLvoxelDirectBlock) % ranks == rank; };
  // Directional lvoxels take the light that reaches them without the forward peaks
  // (delta-M): what the peak scatters goes on with the direct light.
  const bool reduced = light.coefficients() > 1;
  tbb::combinable<rte::SolveCounts> perThread;
  Progress::global().addWork(light.occupiedCount());
  // Cells not this rank's keep the zeros setChannels and occupy gave them.
  tbb::parallel_for(size_t(0), light.occupiedCount(), [&](size_t slot) {
    Progress::global().advance(1);
    if (!mine(slot)) return;
    rte::SolveCounts& local = perThread.local();
    const Vec3 x = light.centre(static_cast<uint32_t>(slot));
    RGB* transmittance = light.transmittance(static_cast<uint32_t>(slot));
    RGB* visibility = light.transmittanceClear(static_cast<uint32_t>(slot));
    for (size_t k = 0; k < deltaCount; ++k) {
      const LightSample s = lights.sampleDelta(lights.lights()[k], x);
      // A spot light's cone does not decide the shadowing: the centre may lie outside the
      // cone while part of the cell is inside, so the transmittance is kept regardless.
      const Light& l = lights.lights()[k];
      const Vec3 wi = l.type == LightType::Directional ? -l.direction : s.wi;
      const float distance = l.type == LightType::Directional ? kInf : length(l.position - x);
      const LightPath path = distance > 0.0f
                                 ? lightPath(ctx, volume, x, wi, distance, reduced, local)
                                 : LightPath{true, RGB(1.0f)};
      transmittance[k] = path.transmittance;
      visibility[k] = path.clear();
    }
    Rng rng(ctx.settings.seed ^ 0x1f0e1u, slot);
    // Samples are weighted 1/pdf already: their sum estimates the integral of L dw, and
    // with each medium's phase towards the camera, its in-scatter along camera rays.
    const auto cell = static_cast<uint32_t>(slot);
    const Vec3 viewDir = normalize(x - ctx.world.camera.position);
    RGB* towardsCamera = light.towardsCamera(cell);
    RGB* towardsCameraClear = light.towardsCameraClear(cell);
    RGB* area = light.areaInScatter(cell);  // (1 / 4 pi) sum of L Yhat_k: mean, harmonics
    const int count = light.coefficients();
    lights.forEachAreaSample(x, nullptr, rng, [&](const LightSample& s) {
      const LightPath path = skyCubes && !s.fromEmitter
                                 ? cubePath(ctx, *skyCubes, x, s.wi, s.distance)
                                 : lightPath(ctx, volume, x, s.wi, s.distance, reduced, local);
      const RGB arriving = s.radiance * path.transmittance;
      const RGB arrivingClear = s.radiance * path.clear();
      const float cosTheta = dot(s.wi, viewDir);
      for (size_t m = 0; m < media.size(); ++m) {
        const float phase = media[m].phase.eval(cosTheta);
        towardsCamera[m] += arriving * phase;
        towardsCameraClear[m] += arrivingClear * phase;
      }
      float yhat[kShCoefficients];
      shBasis(s.wi, count, yhat);
      for (int k = 0; k < count; ++k) area[k] += arriving * (yhat[k] * kInv4Pi);
    });
  });
  perThread.combine_each([&](const rte::SolveCounts& c) { counts += c; });
  if (team.distributed()) light.sumDirectOverRanks(team);
  light.finishCameraChannels();
  size_t lit = 0;
  for (size_t slot = 0; slot < light.occupiedCount(); slot += kLvoxelDirectBlock)
    if (mine(slot)) lit += std::min(kLvoxelDirectBlock, light.occupiedCount() - slot);
  return lit;
}

CutLvoxels markCutLvoxels(const RayTracer& tracer, PointCloud& cloud) {
  LvoxelSet& lvoxels = cloud.mutableLvoxels();
  lvoxels.cut.assign(lvoxels.size(), 0);
  tbb::parallel_for(size_t(0), lvoxels.size(), [&](size_t i) {
    lvoxels.cut[i] = surfaceCutsCube(tracer, lvoxels.position[i], lvoxels.halfSize[i]) ? 1 : 0;
  });
  LvoxelLight& light = lvoxels.light;
  std::vector<uint8_t> near(light.occupiedCount(), 0);
  tbb::parallel_for(size_t(0), near.size(), [&](size_t s) {
    near[s] = surfaceCutsCube(tracer, light.centre(static_cast<uint32_t>(s)), light.grid().spacing);
  });
  CutLvoxels counts;
  for (size_t s = 0; s < near.size(); ++s)
    if (near[s]) {
      light.markNearSurface(static_cast<uint32_t>(s));
      ++counts.cells;
    }
  counts.lvoxels =
      static_cast<size_t>(std::count(lvoxels.cut.begin(), lvoxels.cut.end(), uint8_t{1}));
  return counts;
}

void cloudDirectLight(const LightSet& lights, LvoxelLight& light, uint32_t slot, RGB* out) {
  const RGB* transmittance = light.transmittance(slot);
  const RGB* area = light.areaInScatter(slot);
  const int count = light.coefficients();
  std::copy(area, area + count, out);
  for (size_t k = 0; k < lights.lights().size(); ++k) {
    const LightSample s = lights.sampleDelta(lights.lights()[k], light.centre(slot));
    const RGB arriving = s.radiance * transmittance[k] * kInv4Pi;
    float yhat[kShCoefficients];
    shBasis(s.wi, count, yhat);
    for (int c = 0; c < count; ++c) out[c] += arriving * yhat[c];
  }
}

void PointCloudScatter::testShadow(const Vec3& x, const LightSample& s, size_t k,
                                   LvoxelLightSample& blended) const {
  // The cells' visibility of the light, blended: 1 where every corner sees it, 0 where
  // none does (a delta light's is the same in every colour).
  const float visible = blended.visibility[k].x;
  const bool edge = visible > 0.0f && visible < 1.0f;
  if (!(edge || (shadowRayTests == CameraShadowRays::kAll && visible > 0.0f))) return;
  if (shadowRays) ++*shadowRays;
  // Visible: the media's part alone (the blend over the corners the light reaches).
  blended.transmittance[k] = tracer->occluded(shadowRayFrom(x, s.wi, s.distance))
                                 ? RGB(0.0f)
                                 : blended.transmittance[k] / visible;
}

RGB PointCloudScatter::operator()(const Vec3& x, const Vec3& viewDir,
                                  const MediumCoefficients* perMedium) const {
  thread_local LvoxelLightSample cached;
  if (!light.interpolate(x, cached, tracer)) return RGB(0.0f);
  const int count = light.coefficients();
  float yhat[kShCoefficients];
  shBasis(viewDir, count, yhat);  // light leaving towards the camera came from behind x
  const size_t deltaCount = lights.lights().size();
  // Light samples of the delta lights at x: exact direction, falloff and spot profile.
  thread_local std::vector<LightSample> samples;
  samples.resize(deltaCount);
  for (size_t k = 0; k < deltaCount; ++k) samples[k] = lights.sampleDelta(lights.lights()[k], x);
  if (tracer && shadowRayTests != CameraShadowRays::kNone)
    for (size_t k = 0; k < deltaCount; ++k)
      if (!isBlack(samples[k].radiance)) testShadow(x, samples[k], k, cached);
  RGB source(0.0f);
  for (size_t m = 0; m < media.size(); ++m) {
    if (isBlack(perMedium[m].sigmaS)) continue;
    const PhaseFunction& phase = media[m].phase;
    // The cloud's multiple scattering, scattered towards the camera with the medium's own
    // phase: its full moments, since camera rays see the unreduced medium (the forward
    // peak's share f of sigma_s sends on the light that arrives from straight behind,
    // f + (1 - f) chi*_l = chi_l).
    RGB multiple[kShCoefficients];
    multiple[0] = cached.multiScatter[0];  // (the mean: moment 1)
    for (int c = 1; c < count; ++c)
      multiple[c] = cached.multiScatter[static_cast<size_t>(c)] * phase.moment(shBand(c));
    RGB incident = cached.towardsCamera[m] + shDot(multiple, yhat, count);
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
