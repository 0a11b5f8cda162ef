#include "volume/volume_settings.h"

#include "src/core/names.h"

namespace lvox {
namespace {

constexpr std::string_view kAuto = "auto";
constexpr Named<MajorantKind> kMajorantNames[] = {{MajorantKind::kGrid, "grid"},
                                                  {MajorantKind::kGlobal, "global"}};

}  // namespace

std::optional<rte::Method> parseSolver(std::string_view name, const std::string& file,
                                       const std::string& field) {
  if (name == kAuto) return std::nullopt;
  return rte::parseMethod(name, file, field, kAuto);
}

std::string_view solverName(const std::optional<rte::Method>& solver) {
  return solver ? rte::methodName(*solver) : kAuto;
}

MajorantKind parseMajorant(std::string_view name, const std::string& file,
                           const std::string& field) {
  return parseNamed(name, kMajorantNames, "majorant", file, field);
}

std::string_view majorantName(MajorantKind m) { return nameOf(m, kMajorantNames); }

VolumeSettings parseVolumeSettings(JsonObject v) {
  VolumeSettings s;
  s.solver = v.choice("solver", std::string(kAuto), parseSolver);
  if (v.has("step")) s.step = v.number("step", kStepRange, std::nullopt);
  s.stepScale = v.number("step_scale", kStepScaleRange, s.stepScale);
  if (s.step && v.has("step_scale"))
    v.fail("step_scale", "scales the relative step; the scene gives an absolute \"step\"");
  s.tolerance = v.number("tolerance", kToleranceRange, s.tolerance);
  if (v.has("min_step")) s.minStep = v.number("min_step", 1e-9f, 1e9f, std::nullopt);
  if (v.has("max_step")) s.maxStep = v.number("max_step", 1e-9f, 1e9f, std::nullopt);
  if (s.minStep && s.maxStep && *s.minStep > *s.maxStep) v.fail("min_step", "exceeds max_step");
  s.interpolation = v.choice("interpolation", std::string(interpolationName(s.interpolation)),
                             parseInterpolation);
  s.sampling = v.choice("sampling", std::string(rte::samplingName(s.sampling)),
                        [](std::string_view n, const std::string& f, const std::string& k) {
                          return rte::parseSampling(n, f, k);
                        });
  s.maxEvaluations = static_cast<uint32_t>(
      v.integer("max_evaluations", 1, 1 << 30, static_cast<int>(s.maxEvaluations)));
  s.majorant = v.choice("majorant", std::string(majorantName(s.majorant)), parseMajorant);
  s.shadowCache = v.integer("shadow_cache", 0, 1024, s.shadowCache);
  s.environmentCache = v.integer("environment_cache", 0, 256, s.environmentCache);
  s.environmentDirections =
      v.integer("environment_cache_directions", 16, 4096, s.environmentDirections);
  v.finish();
  return s;
}

SettingList describe(const VolumeSettings& s) {
  SettingList l;
  const std::string v = "volume_integrator.";
  l.add(v + "solver", solverName(s.solver));
  // An absent length is relative to the media (VolumeSettings).
  auto length = [&](const char* key, const std::optional<float>& value) {
    if (value)
      l.add(v + key, *value);
    else
      l.add(v + key, "relative");
  };
  length("step", s.step);
  l.add(v + "step_scale", s.stepScale);
  l.add(v + "tolerance", s.tolerance);
  length("min_step", s.minStep);
  length("max_step", s.maxStep);
  l.add(v + "interpolation", interpolationName(s.interpolation));
  l.add(v + "sampling", rte::samplingName(s.sampling));
  l.add(v + "max_evaluations", s.maxEvaluations);
  l.add(v + "majorant", majorantName(s.majorant));
  l.add(v + "shadow_cache", s.shadowCache);
  l.add(v + "environment_cache", s.environmentCache);
  l.add(v + "environment_cache_directions", s.environmentDirections);
  return l;
}

}  // namespace lvox
