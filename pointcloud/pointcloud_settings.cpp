#include "pointcloud/pointcloud_settings.h"

#include <algorithm>
#include <cstdint>
#include <string>

#include "src/core/error.h"
#include "src/core/math.h"
#include "src/core/names.h"

namespace lvox {
namespace {

constexpr Named<GatherVisibility> kVisibilityNames[] = {{GatherVisibility::kCloud, "cloud"},
                                                        {GatherVisibility::kRays, "rays"}};
constexpr Named<SurfelSamplerKind> kSamplerNames[] = {{SurfelSamplerKind::kUniform, "uniform"},
                                                      {SurfelSamplerKind::kCamera, "camera"}};
constexpr Named<LvoxelOwnCube> kOwnCubeNames[] = {{LvoxelOwnCube::kRays, "rays"},
                                                  {LvoxelOwnCube::kQuadrature, "quadrature"}};
constexpr Named<LvoxelExtinction> kExtinctionNames[] = {
    {LvoxelExtinction::kMean, "mean"}, {LvoxelExtinction::kTransmittance, "transmittance"}};
constexpr Named<CameraShadowRays> kCameraShadowRaysNames[] = {{CameraShadowRays::kEdges, "edges"},
                                                              {CameraShadowRays::kAll, "all"},
                                                              {CameraShadowRays::kNone, "none"}};
constexpr Named<IndirectShadowMedia> kIndirectShadowMediaNames[] = {
    {IndirectShadowMedia::kCubes, "cubes"}, {IndirectShadowMedia::kMedia, "media"}};
constexpr Named<BounceTail> kTailNames[] = {{BounceTail::kNone, "none"},
                                            {BounceTail::kGeometric, "geometric"}};
constexpr Named<SurfelRayAllocation> kAllocationNames[] = {
    {SurfelRayAllocation::kUniform, "uniform"}, {SurfelRayAllocation::kVariance, "variance"}};
constexpr Named<GatherFit> kFitNames[] = {{GatherFit::kConstant, "constant"},
                                          {GatherFit::kLinear, "linear"}};
constexpr Named<LvoxelLightBlend> kBlendNames[] = {{LvoxelLightBlend::kLinear, "linear"},
                                                   {LvoxelLightBlend::kExponential, "exponential"}};

// A whole number in [lo, hi] (a JSON number) or "auto" (a string, or the key absent), which
// gives `autoValue`; `what` names the number in the errors ("a count of rays").
int countOrAuto(JsonObject& p, const std::string& key, const std::string& what, int lo, int hi,
                int autoValue) {
  const nlohmann::json* given = p.has(key) ? &p.raw(key) : nullptr;
  if (given && !given->is_number() && !given->is_string())
    p.fail(key, "expected " + what + " or \"auto\", got " + given->type_name());
  if (given && given->is_number()) return p.integer(key, lo, hi, std::nullopt);
  return p.choice(
      key, "auto", [&](std::string_view text, const std::string& file, const std::string& field) {
        if (text != "auto")
          throw InputError(file, field,
                           "expected " + what + " or \"auto\", got \"" + std::string(text) + "\"");
        return autoValue;
      });
}

}  // namespace

GatherVisibility parseGatherVisibility(std::string_view name, const std::string& file,
                                       const std::string& field) {
  return parseNamed(name, kVisibilityNames, "visibility", file, field);
}

std::string_view gatherVisibilityName(GatherVisibility v) { return nameOf(v, kVisibilityNames); }

SurfelSamplerKind parseSurfelSampler(std::string_view name, const std::string& file,
                                     const std::string& field) {
  return parseNamed(name, kSamplerNames, "sampler", file, field);
}

std::string_view surfelSamplerName(SurfelSamplerKind s) { return nameOf(s, kSamplerNames); }

LvoxelOwnCube parseLvoxelOwnCube(std::string_view name, const std::string& file,
                                 const std::string& field) {
  return parseNamed(name, kOwnCubeNames, "own-cube integration", file, field);
}

std::string_view lvoxelOwnCubeName(LvoxelOwnCube o) { return nameOf(o, kOwnCubeNames); }

LvoxelExtinction parseLvoxelExtinction(std::string_view name, const std::string& file,
                                       const std::string& field) {
  return parseNamed(name, kExtinctionNames, "lvoxel extinction", file, field);
}

std::string_view lvoxelExtinctionName(LvoxelExtinction e) { return nameOf(e, kExtinctionNames); }

CameraShadowRays parseCameraShadowRays(std::string_view name, const std::string& file,
                                       const std::string& field) {
  return parseNamed(name, kCameraShadowRaysNames, "camera shadow rays", file, field);
}

IndirectShadowMedia parseIndirectShadowMedia(std::string_view name, const std::string& file,
                                             const std::string& field) {
  return parseNamed(name, kIndirectShadowMediaNames, "indirect shadow media", file, field);
}

std::string_view indirectShadowMediaName(IndirectShadowMedia s) {
  return nameOf(s, kIndirectShadowMediaNames);
}

std::string_view cameraShadowRaysName(CameraShadowRays c) {
  return nameOf(c, kCameraShadowRaysNames);
}

BounceTail parseBounceTail(std::string_view name, const std::string& file,
                           const std::string& field) {
  return parseNamed(name, kTailNames, "tail", file, field);
}

std::string_view bounceTailName(BounceTail t) { return nameOf(t, kTailNames); }

SurfelRayAllocation parseSurfelRayAllocation(std::string_view name, const std::string& file,
                                             const std::string& field) {
  return parseNamed(name, kAllocationNames, "ray allocation", file, field);
}

std::string_view surfelRayAllocationName(SurfelRayAllocation a) {
  return nameOf(a, kAllocationNames);
}

GatherFit parseGatherFit(std::string_view name, const std::string& file, const std::string& field) {
  return parseNamed(name, kFitNames, "fit", file, field);
}

std::string_view gatherFitName(GatherFit f) { return nameOf(f, kFitNames); }

LvoxelLightBlend parseLvoxelLightBlend(std::string_view name, const std::string& file,
                                       const std::string& field) {
  return parseNamed(name, kBlendNames, "blend", file, field);
}

std::string_view lvoxelLightBlendName(LvoxelLightBlend b) { return nameOf(b, kBlendNames); }

int finalGatherSamples(const PointCloudSettings& s, uint64_t cloudGatherRays,
                       uint64_t finalGatherPoints) {
  if (s.gatherSamples != kAutoGatherSamples) return s.gatherSamples;
  constexpr uint64_t kMultiple = 16;  // strataGrid then finds rows and columns near square
  const uint64_t points = std::max<uint64_t>(finalGatherPoints, 1);
  const uint64_t perPoint = (cloudGatherRays + points - 1) / points;
  const uint64_t rounded = (perPoint + kMultiple - 1) / kMultiple * kMultiple;
  return static_cast<int>(
      std::clamp<uint64_t>(rounded, kMinAutoGatherSamples, kMaxAutoGatherSamples));
}

int gatherLightSamplesBase(const PointCloudSettings& s) {
  return s.gatherSamples == kAutoGatherSamples ? kMinAutoGatherSamples : s.gatherSamples;
}

float defaultLvoxelClusterSolidAngle(GatherVisibility v) {
  return v == GatherVisibility::kCloud ? 0.03f : 0.0f;
}

PointCloudSettings parsePointCloudSettings(JsonObject p) {
  PointCloudSettings s;
  s.surfelSpacing = p.number("surfel_spacing", 0.0f, 1e9f, s.surfelSpacing);
  s.lvoxelSpacing = p.number("lvoxel_spacing", 0.0f, 1e9f, s.lvoxelSpacing);
  s.lvoxelSamples = p.integer("lvoxel_samples", 1, 8, s.lvoxelSamples);
  s.lvoxelExtinction =
      p.choice("lvoxel_extinction", std::string(lvoxelExtinctionName(s.lvoxelExtinction)),
               parseLvoxelExtinction);
  s.lvoxelGatherSamples = p.integer("lvoxel_gather_samples", 1, 1 << 16, s.lvoxelGatherSamples);
  s.lvoxelNearSamples = p.integer("lvoxel_near_samples", 1, 1 << 16, s.lvoxelNearSamples);
  s.lvoxelNearReach = p.number("lvoxel_near_reach", 0.0f, 1e3f, s.lvoxelNearReach);
  s.lvoxelOwnCube = p.choice("lvoxel_own_cube", std::string(lvoxelOwnCubeName(s.lvoxelOwnCube)),
                             parseLvoxelOwnCube);
  s.gatherSpacing = p.integer("gather_spacing", 1, 64, s.gatherSpacing);
  s.gatherFilter = p.number("gather_filter", 1.0f, 16.0f, s.gatherFilter);
  s.gatherFit = p.choice("gather_fit", std::string(gatherFitName(s.gatherFit)), parseGatherFit);
  s.bounces = p.integer("bounces", 0, 1024, s.bounces);
  s.bounceTolerance = p.number("bounce_tolerance", 0.0f, 1.0f, s.bounceTolerance);
  s.bounceTail =
      p.choice("bounce_tail", std::string(bounceTailName(s.bounceTail)), parseBounceTail);
  s.bounceMixingDepth = countOrAuto(p, "bounce_mixing_depth", "a depth", 0, 16, kAutoBounceMixing);
  s.surfelLightSamples = p.integer("surfel_light_samples", 1, 1 << 16, s.surfelLightSamples);
  s.lvoxelLightSamples = p.integer("lvoxel_light_samples", 1, 1 << 16, s.lvoxelLightSamples);
  s.lvoxelLightBlend =
      p.choice("lvoxel_light_blend", std::string(lvoxelLightBlendName(s.lvoxelLightBlend)),
               parseLvoxelLightBlend);
  s.cameraShadowRays =
      p.choice("camera_shadow_rays", std::string(cameraShadowRaysName(s.cameraShadowRays)),
               parseCameraShadowRays);
  s.indirectShadowMedia =
      p.choice("indirect_shadow_media", std::string(indirectShadowMediaName(s.indirectShadowMedia)),
               parseIndirectShadowMedia);
  s.lvoxelSkyShadowMedia = p.choice("lvoxel_sky_shadow_media",
                                    std::string(indirectShadowMediaName(s.lvoxelSkyShadowMedia)),
                                    parseIndirectShadowMedia);
  s.burialReach = p.number("burial_reach", 0.0f, 1e3f, s.burialReach);
  s.gatherVisibility =
      p.choice("gather_visibility", std::string(gatherVisibilityName(s.gatherVisibility)),
               parseGatherVisibility);
  s.hitLatticeStep = p.number("hit_lattice_step", 0.0f, 16.0f, s.hitLatticeStep);
  s.surfelGatherSamples = p.integer("surfel_gather_samples", 1, 1 << 16, s.surfelGatherSamples);
  s.surfelGatherAllocation = p.choice(
      "surfel_gather_allocation", std::string(surfelRayAllocationName(s.surfelGatherAllocation)),
      parseSurfelRayAllocation);
  s.targetSurfels = p.integer("target_surfels", 1, 10'000'000, s.targetSurfels);
  s.surfelSampler = p.choice("surfel_sampler", std::string(surfelSamplerName(s.surfelSampler)),
                             parseSurfelSampler);
  s.gatherSamples =
      countOrAuto(p, "gather_samples", "a count of rays", 1, 1 << 16, kAutoGatherSamples);
  s.gatherLightSamples = p.integer("gather_light_samples", 0, 1 << 16, s.gatherLightSamples);
  if (s.gatherLightSamples >= gatherLightSamplesBase(s))
    p.fail("gather_light_samples",
           "must be less than " +
               (s.gatherSamples == kAutoGatherSamples
                    ? "the " + std::to_string(kMinAutoGatherSamples) +
                          " rays that \"gather_samples\": \"auto\" gives at least"
                    : "gather_samples (" + std::to_string(s.gatherSamples) + ")") +
               ": a gather keeps a cosine ray");
  s.lvoxelClusterSolidAngle = p.number("lvoxel_cluster_solid_angle", 0.0f, 4.0f * kPi,
                                       defaultLvoxelClusterSolidAngle(s.gatherVisibility));
  s.clusterSolidAngle = p.number("cluster_solid_angle", 0.0f, 4.0f * kPi, s.clusterSolidAngle);
  if (s.gatherLightSamples > 0 && s.gatherVisibility != GatherVisibility::kRays)
    p.fail("gather_light_samples",
           "needs \"gather_visibility\": \"rays\" (a disk hit has no triangle to aim at)");
  p.finish();
  return s;
}

SettingList describe(const PointCloudSettings& s) {
  SettingList l;
  const std::string p = "pointcloud.";
  l.add(p + "surfel_spacing", s.surfelSpacing);
  l.add(p + "target_surfels", s.targetSurfels);
  l.add(p + "surfel_sampler", surfelSamplerName(s.surfelSampler));
  l.add(p + "lvoxel_spacing", s.lvoxelSpacing);
  l.add(p + "lvoxel_samples", s.lvoxelSamples);
  l.add(p + "lvoxel_extinction", lvoxelExtinctionName(s.lvoxelExtinction));
  l.add(p + "lvoxel_gather_samples", s.lvoxelGatherSamples);
  l.add(p + "lvoxel_near_samples", s.lvoxelNearSamples);
  l.add(p + "lvoxel_near_reach", s.lvoxelNearReach);
  l.add(p + "lvoxel_own_cube", lvoxelOwnCubeName(s.lvoxelOwnCube));
  l.add(p + "bounces", s.bounces);
  l.add(p + "bounce_tolerance", s.bounceTolerance);
  l.add(p + "bounce_tail", bounceTailName(s.bounceTail));
  if (s.bounceMixingDepth == kAutoBounceMixing)
    l.add(p + "bounce_mixing_depth", "auto");
  else
    l.add(p + "bounce_mixing_depth", s.bounceMixingDepth);
  l.add(p + "surfel_light_samples", s.surfelLightSamples);
  l.add(p + "lvoxel_light_samples", s.lvoxelLightSamples);
  l.add(p + "lvoxel_light_blend", lvoxelLightBlendName(s.lvoxelLightBlend));
  l.add(p + "camera_shadow_rays", cameraShadowRaysName(s.cameraShadowRays));
  l.add(p + "indirect_shadow_media", indirectShadowMediaName(s.indirectShadowMedia));
  l.add(p + "lvoxel_sky_shadow_media", indirectShadowMediaName(s.lvoxelSkyShadowMedia));
  l.add(p + "burial_reach", s.burialReach);
  l.add(p + "gather_visibility", gatherVisibilityName(s.gatherVisibility));
  l.add(p + "hit_lattice_step", s.hitLatticeStep);
  l.add(p + "surfel_gather_samples", s.surfelGatherSamples);
  l.add(p + "surfel_gather_allocation", surfelRayAllocationName(s.surfelGatherAllocation));
  if (s.gatherSamples == kAutoGatherSamples)
    l.add(p + "gather_samples", "auto");
  else
    l.add(p + "gather_samples", s.gatherSamples);
  l.add(p + "gather_light_samples", s.gatherLightSamples);
  l.add(p + "gather_spacing", s.gatherSpacing);
  l.add(p + "gather_filter", s.gatherFilter);
  l.add(p + "gather_fit", gatherFitName(s.gatherFit));
  l.add(p + "lvoxel_cluster_solid_angle", s.lvoxelClusterSolidAngle);
  l.add(p + "cluster_solid_angle", s.clusterSolidAngle);
  return l;
}

}  // namespace lvox
