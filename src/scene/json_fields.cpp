#include "src/scene/json_fields.h"

#include <cmath>
#include <sstream>

namespace lvox {

JsonObject::JsonObject(const nlohmann::json& value, std::string file, std::string path)
    : value_(value), file_(std::move(file)), path_(std::move(path)) {
  if (!value_.is_object())
    throw InputError(file_, path_.empty() ? "(top level)" : path_, "must be an object");
}

std::string JsonObject::fieldPath(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void JsonObject::fail(const std::string& key, const std::string& what) const {
  throw InputError(file_, fieldPath(key), what);
}

bool JsonObject::has(const std::string& key) const { return value_.contains(key); }

const nlohmann::json& JsonObject::lookup(const std::string& key) {
  used_.insert(key);
  auto it = value_.find(key);
  if (it == value_.end()) fail(key, "missing required field");
  return *it;
}

const nlohmann::json& JsonObject::raw(const std::string& key) { return lookup(key); }

float JsonObject::toFinite(const nlohmann::json& v, const std::string& key) const {
  if (!v.is_number()) fail(key, "expected a number, got " + std::string(v.type_name()));
  const double d = v.get<double>();
  if (!std::isfinite(d) || std::abs(d) > 3.0e38) fail(key, "number is not finite");
  return static_cast<float>(d);
}

float JsonObject::number(const std::string& key, std::optional<float> fallback) {
  if (!has(key) && fallback) {
    used_.insert(key);
    return *fallback;
  }
  return toFinite(lookup(key), key);
}

float JsonObject::number(const std::string& key, float lo, float hi,
                         std::optional<float> fallback) {
  const float v = number(key, fallback);
  if (v < lo || v > hi) {
    std::ostringstream s;
    s << "value " << v << " is outside [" << lo << ", " << hi << "]";
    fail(key, s.str());
  }
  return v;
}

int JsonObject::integer(const std::string& key, int lo, int hi, std::optional<int> fallback) {
  if (!has(key) && fallback) {
    used_.insert(key);
    return *fallback;
  }
  const nlohmann::json& v = lookup(key);
  if (!v.is_number_integer()) fail(key, "expected an integer, got " + std::string(v.type_name()));
  const long long i = v.get<long long>();
  if (i < lo || i > hi) {
    std::ostringstream s;
    s << "value " << i << " is outside [" << lo << ", " << hi << "]";
    fail(key, s.str());
  }
  return static_cast<int>(i);
}

std::string JsonObject::string(const std::string& key, std::optional<std::string> fallback) {
  if (!has(key) && fallback) {
    used_.insert(key);
    return *fallback;
  }
  const nlohmann::json& v = lookup(key);
  if (!v.is_string()) fail(key, "expected a string, got " + std::string(v.type_name()));
  return v.get<std::string>();
}

Vec3 JsonObject::vec3(const std::string& key, std::optional<Vec3> fallback) {
  if (!has(key) && fallback) {
    used_.insert(key);
    return *fallback;
  }
  const nlohmann::json& v = lookup(key);
  if (!v.is_array() || v.size() != 3) fail(key, "expected an array of 3 numbers");
  return {toFinite(v[0], key), toFinite(v[1], key), toFinite(v[2], key)};
}

RGB JsonObject::rgb(const std::string& key, float lo, float hi, std::optional<RGB> fallback) {
  if (!has(key) && fallback) {
    used_.insert(key);
    return *fallback;
  }
  const nlohmann::json& v = lookup(key);
  RGB c;
  if (v.is_number()) {
    const float g = toFinite(v, key);
    c = RGB(g, g, g);
  } else if (v.is_array() && v.size() == 3) {
    c = RGB(toFinite(v[0], key), toFinite(v[1], key), toFinite(v[2], key));
  } else {
    fail(key, "expected [r, g, b] or a number");
  }
  for (int i = 0; i < 3; ++i)
    if (c[i] < lo || c[i] > hi) {
      std::ostringstream s;
      s << "channel value " << c[i] << " is outside [" << lo << ", " << hi << "]";
      fail(key, s.str());
    }
  return c;
}

JsonObject JsonObject::object(const std::string& key) {
  return JsonObject(lookup(key), file_, fieldPath(key));
}

std::vector<nlohmann::json> JsonObject::array(const std::string& key, bool required) {
  if (!has(key) && !required) {
    used_.insert(key);
    return {};
  }
  const nlohmann::json& v = lookup(key);
  if (!v.is_array()) fail(key, "expected an array, got " + std::string(v.type_name()));
  return std::vector<nlohmann::json>(v.begin(), v.end());
}

void JsonObject::finish() const {
  for (auto it = value_.begin(); it != value_.end(); ++it)
    if (!used_.count(it.key())) fail(it.key(), "unknown field (misspelled?)");
}

}  // namespace lvox
