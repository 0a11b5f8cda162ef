#pragma once
// Reads a scene file (format: docs/scene-format.md) and composes the scene: each section
// is parsed by the library that owns it (the world by src/world, media and the volume
// integrator by volume/, the point cloud by pointcloud/, the render by src/render).
//
// Command-line flags are merged into the document before parsing (SettingOverride), so a
// flag's value passes exactly the checks of the field it sets and an error names the flag.
// Every setting is parsed and checked before any mesh or grid is loaded.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "src/scene/scene.h"

namespace lvox {

// A command-line flag that sets one field of a section: {"--solver", "volume_integrator",
// "solver", "rk4"}.
struct SettingOverride {
  std::string flag;
  std::string section;
  std::string key;
  nlohmann::json value;
};

// The scene field a command-line flag sets; one table for every subcommand.
struct FlagField {
  const char* flag;
  const char* section;
  const char* key;
};
namespace flags {
inline constexpr FlagField kMode{"--mode", "render", "mode"};
inline constexpr FlagField kSpp{"--spp", "render", "spp"};
inline constexpr FlagField kAdaptiveSpp{"--adaptive-spp", "render", "adaptive_spp"};
inline constexpr FlagField kMaxBounces{"--max-bounces", "render", "max_bounces"};
inline constexpr FlagField kSeed{"--seed", "render", "seed"};
inline constexpr FlagField kThreads{"--threads", "render", "threads"};
inline constexpr FlagField kMaxMemory{"--max-memory", "render", "max_memory"};
inline constexpr FlagField kMaxEvaluations{"--max-evaluations", "render", "max_evaluations"};
inline constexpr FlagField kWidth{"--width", "camera", "width"};
inline constexpr FlagField kHeight{"--height", "camera", "height"};
inline constexpr FlagField kSolver{"--solver", "volume_integrator", "solver"};
inline constexpr FlagField kStep{"--step", "volume_integrator", "step"};
inline constexpr FlagField kTolerance{"--tol", "volume_integrator", "tolerance"};
}  // namespace flags

// Appends the override of `field` when the flag was given.
template <class T>
void addOverride(std::vector<SettingOverride>& out, const FlagField& field,
                 const std::optional<T>& value) {
  if (value) out.push_back({field.flag, field.section, field.key, *value});
}

// Throws InputError naming the file and field (or the flag) on any problem; unknown keys
// are errors, not ignored.
Scene loadScene(const std::string& path, const std::vector<SettingOverride>& overrides = {});

// The same, from JSON text; `path` is used for messages and to resolve relative file names.
Scene parseScene(const std::string& text, const std::string& path,
                 const std::vector<SettingOverride>& overrides = {});

}  // namespace lvox
