#pragma once
// Typed, validated access to JSON scene fields. Every accessor knows the field's path
// ("lights[2].intensity") and the file, so every error names both. Objects remember
// which keys were read, and `finish()` rejects the ones nobody asked for (typos).
//
// A value may have come from a command-line flag instead of the file (src/scene merges
// flags into the document before parsing, so flags and files share every check): the
// document's `FlagSources` map such field paths to the flag, and errors about them name
// the flag.
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "src/core/error.h"
#include "src/core/math.h"

namespace lvox {

// Inclusive bounds of a number setting, shared by a section's parser and any command-line
// check of the same quantity.
struct NumberRange {
  float lo, hi;
};

// Throws InputError(file, field, "value v is outside [lo, hi]") unless lo <= v <= hi (NaN
// is outside).
void checkRange(float value, NumberRange range, const std::string& file, const std::string& field);

// Field path ("volume_integrator.solver") -> the flag that gave its value ("--solver").
using FlagSources = std::map<std::string, std::string>;

// Where an error about a value points: the file and field, or the flag that gave it.
struct ValueSource {
  std::string file;
  std::string field;  // empty for a flag
};

class JsonObject {
 public:
  JsonObject(const nlohmann::json& value, std::string file, std::string path,
             std::shared_ptr<const FlagSources> flags = nullptr);

  bool has(const std::string& key) const;
  float number(const std::string& key, std::optional<float> fallback = std::nullopt);
  // A number with inclusive bounds.
  float number(const std::string& key, float lo, float hi, std::optional<float> fallback);
  float number(const std::string& key, NumberRange range, std::optional<float> fallback) {
    return number(key, range.lo, range.hi, fallback);
  }
  int integer(const std::string& key, int lo, int hi, std::optional<int> fallback = std::nullopt);
  std::string string(const std::string& key, std::optional<std::string> fallback = std::nullopt);
  Vec3 vec3(const std::string& key, std::optional<Vec3> fallback = std::nullopt);
  // A colour: [r,g,b] or a single number for grey; each channel in [lo, hi].
  RGB rgb(const std::string& key, float lo, float hi, std::optional<RGB> fallback = std::nullopt);
  // A file name, resolved against the folder of the JSON file when relative.
  std::string filePath(const std::string& key);
  // A name parsed by `parse(name, file, field)`, the library's own parse function for an
  // enumeration, which throws InputError naming the source of the value on a bad name.
  template <class Parse>
  auto choice(const std::string& key, std::optional<std::string> fallback, Parse&& parse) {
    const std::string name = string(key, fallback);
    const ValueSource src = source(key);
    return parse(name, src.file, src.field);
  }
  JsonObject object(const std::string& key);
  // The elements of an array; `required` false gives an empty list when absent.
  std::vector<nlohmann::json> array(const std::string& key, bool required = false);
  const nlohmann::json& raw(const std::string& key);

  // Throws for every key present in the object but never read.
  void finish() const;

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }  // of this object: "media[2]"
  // The keys present in the object (all of them count as read).
  std::vector<std::string> keys();
  std::string fieldPath(const std::string& key) const;
  ValueSource source(const std::string& key) const;
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  const nlohmann::json& lookup(const std::string& key);
  float toFinite(const nlohmann::json& v, const std::string& key) const;

  const nlohmann::json& value_;
  std::string file_;
  std::string path_;
  std::set<std::string> used_;
  std::shared_ptr<const FlagSources> flags_;
};

// An affine transform: {"matrix": [16 numbers, row-major]} or {"translate", "rotate":
// {"axis", "deg"}, "scale"} applied as T R S; identity when `key` is absent. Singular
// transforms are refused.
Transform parseTransform(JsonObject& parent, const std::string& key);

}  // namespace lvox
