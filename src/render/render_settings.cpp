#include "src/render/render_settings.h"

#include <limits>

#include "src/core/error.h"
#include "src/core/memory_budget.h"
#include "src/core/names.h"
#include "src/core/work_budget.h"

namespace lvox {
namespace {

constexpr Named<Mode> kModeNames[] = {{Mode::kPcb, "pcb"},
                                      {Mode::kPcbSurfels, "pcb-surfels"},
                                      {Mode::kDirect, "direct"},
                                      {Mode::kMc, "mc"}};

int parseAutoAdaptive(std::string_view text, const std::string& file, const std::string& field) {
  if (text == "auto") return RenderSettings::kAutoAdaptive;
  throw InputError(file, field, "must be \"auto\" or a whole number of samples per pixel");
}

}  // namespace

int adaptiveSamplesFor(const RenderSettings& s) {
  if (s.adaptiveSpp != RenderSettings::kAutoAdaptive) return s.adaptiveSpp;
  return isPointBased(s.mode) && s.spp >= 2 ? (3 * s.spp + 1) / 2 : 0;
}

Mode parseMode(std::string_view name, const std::string& file, const std::string& field) {
  return parseNamed(name, kModeNames, "mode", file, field);
}

std::string_view modeName(Mode mode) { return nameOf(mode, kModeNames); }
std::string modeNames() { return namesOf(kModeNames); }

RenderSettings parseRenderSettings(JsonObject r) {
  RenderSettings s;
  s.mode = r.choice("mode", std::string(modeName(s.mode)), parseMode);
  s.spp = r.integer("spp", 1, 1 << 20, s.spp);
  s.adaptiveSpp = r.has("adaptive_spp") && r.raw("adaptive_spp").is_number()
                      ? r.integer("adaptive_spp", 0, 1 << 20, 0)
                      : r.choice("adaptive_spp", "auto", parseAutoAdaptive);
  if (s.adaptiveSpp > 0 && s.adaptiveSpp <= s.spp)
    r.fail("adaptive_spp",
           "must be 0 (none) or more than render.spp (" + std::to_string(s.spp) + ")");
  s.maxBounces = r.integer("max_bounces", 0, 1 << 16, s.maxBounces);
  s.seed = static_cast<uint64_t>(
      r.integer("seed", 0, std::numeric_limits<int>::max(), static_cast<int>(s.seed)));
  s.areaLightSamples = r.integer("area_light_samples", 1, 1 << 16, s.areaLightSamples);
  s.mediumLightSamples = r.integer("medium_light_samples", 1, 1 << 16, s.mediumLightSamples);
  s.emitterSamples = r.integer("emitter_samples", 1, 1 << 12, s.emitterSamples);
  s.threads = r.integer("threads", 0, 1024, s.threads);
  s.maxMemory =
      r.choice("max_memory", "auto",
               [](std::string_view text, const std::string& file, const std::string& field) {
                 return text == "auto" ? uint64_t(0) : parseByteSize(text, file, field);
               });
  // A count: a JSON number (5e10) or a string ("5e10", "auto", what --max-evaluations gives).
  s.maxEvaluations =
      r.has("max_evaluations") && r.raw("max_evaluations").is_number()
          ? static_cast<uint64_t>(r.number("max_evaluations", 1e6f, 1e18f, std::nullopt))
          : r.choice("max_evaluations", "auto", parseEvaluationCount);
  r.finish();
  return s;
}

SettingList describe(const RenderSettings& s) {
  SettingList l;
  l.add("render.mode", modeName(s.mode));
  l.add("render.seed", std::to_string(s.seed));
  l.add("render.adaptive_spp", s.adaptiveSpp == RenderSettings::kAutoAdaptive
                                   ? std::string("auto")
                                   : std::to_string(s.adaptiveSpp));
  l.add("render.max_bounces", s.maxBounces);
  l.add("render.area_light_samples", s.areaLightSamples);
  l.add("render.medium_light_samples", s.mediumLightSamples);
  l.add("render.emitter_samples", s.emitterSamples);
  return l;
}

}  // namespace lvox
