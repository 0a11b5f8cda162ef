#pragma once
// Typed, validated access to JSON scene fields. Every accessor knows the field's path
// ("lights[2].intensity") and the file, so every error names both. Objects remember
// which keys were read, and `finish()` rejects the ones nobody asked for (typos).
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "src/core/error.h"
#include "src/core/math.h"

namespace lvox {

class JsonObject {
 public:
  JsonObject(const nlohmann::json& value, std::string file, std::string path);

  bool has(const std::string& key) const;
  float number(const std::string& key, std::optional<float> fallback = std::nullopt);
  // A number with inclusive bounds.
  float number(const std::string& key, float lo, float hi, std::optional<float> fallback);
  int integer(const std::string& key, int lo, int hi, std::optional<int> fallback = std::nullopt);
  std::string string(const std::string& key, std::optional<std::string> fallback = std::nullopt);
  Vec3 vec3(const std::string& key, std::optional<Vec3> fallback = std::nullopt);
  // A colour: [r,g,b] or a single number for grey; each channel in [lo, hi].
  RGB rgb(const std::string& key, float lo, float hi, std::optional<RGB> fallback = std::nullopt);
  JsonObject object(const std::string& key);
  // The elements of an array; `required` false gives an empty list when absent.
  std::vector<nlohmann::json> array(const std::string& key, bool required = false);
  const nlohmann::json& raw(const std::string& key);

  // Throws for every key present in the object but never read.
  void finish() const;

  const std::string& file() const { return file_; }
  std::string fieldPath(const std::string& key) const;
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  const nlohmann::json& lookup(const std::string& key);
  float toFinite(const nlohmann::json& v, const std::string& key) const;

  const nlohmann::json& value_;
  std::string file_;
  std::string path_;
  std::set<std::string> used_;
};

}  // namespace lvox
