#pragma once
// Settings of the volume integrator (the scene file's "volume_integrator" section and the
// --solver, --step and --tol flags), typed, with their parser beside them.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "src/core/json_fields.h"
#include "src/core/setting_list.h"
#include "volume/media/interpolation.h"
#include "volume/rte/method.h"

namespace lvox {

// How free-flight sampling bounds sigma_t in mc mode: per 8^3 block of a VDB grid, or one
// majorant per medium.
enum class MajorantKind { kGrid, kGlobal };

inline constexpr NumberRange kStepRange{1e-6f, 1e9f};  // scene units
inline constexpr NumberRange kStepScaleRange{1e-3f, 1e3f};
inline constexpr NumberRange kToleranceRange{1e-12f, 1.0f};

struct VolumeSettings {
  std::optional<rte::Method> solver;  // empty: "auto", chosen per ray segment
  // Steps in scene units where the scene gives them. Where it does not, each ray segment's
  // steps are relative to the media on it (src/render/medium_scale.h): the natural step
  // times `stepScale`, min_step a thousandth of it and max_step ten times it.
  std::optional<float> step;
  float stepScale = 1.0f;
  // Multiplies the step, absolute or relative.
  void scaleStep(float k) {
    if (step)
      *step *= k;
    else
      stepScale *= k;
  }
  float tolerance = 1e-3f;
  std::optional<float> minStep;
  std::optional<float> maxStep;
  Interpolation interpolation = Interpolation::Trilinear;
  rte::Sampling sampling = rte::Sampling::kNone;
  uint32_t maxEvaluations = 100000;  // per ray segment, then degrade gracefully
  MajorantKind majorant = MajorantKind::kGrid;
  // Direct mode's shadow rays to point, spot and directional lights: 0 solves each one;
  // N > 0 looks the transmittance up in a grid of N cells along the media's longest side
  // per light, solved once per node (src/render/transmittance_cache.h).
  int shadowCache = 64;
  // Direct mode's constant environment in the media: 0 samples a random direction and solves
  // its shadow ray at every in-scatter sample; N > 0 caches the light arriving from the
  // environment as spherical harmonics on a grid of N cells along the heterogeneous media's
  // longest side, each node projecting `environmentDirections` shadow rays
  // (src/render/environment_cache.h).
  int environmentCache = 24;
  int environmentDirections = 32;
};

// Reads the "volume_integrator" object; unknown keys and out-of-range values throw.
VolumeSettings parseVolumeSettings(JsonObject v);
// Every field, as "volume_integrator.<key>" and the value the parser reads back.
SettingList describe(const VolumeSettings& s);

// "auto" (empty) or a method name of volume/rte/method.h.
std::optional<rte::Method> parseSolver(std::string_view name, const std::string& file,
                                       const std::string& field);
std::string_view solverName(const std::optional<rte::Method>& solver);

MajorantKind parseMajorant(std::string_view name, const std::string& file,
                           const std::string& field);
std::string_view majorantName(MajorantKind m);

}  // namespace lvox
