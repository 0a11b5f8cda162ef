#include "src/core/json_fields.h"

#include <cmath>
#include <filesystem>
#include <sstream>

namespace lvox {

JsonObject::JsonObject(const nlohmann::json& value, std::string file, std::string path,
                       std::shared_ptr<const FlagSources> flags)
    : value_(value), file_(std::move(file)), path_(std::move(path)), flags_(std::move(flags)) {
  if (!value_.is_object())
    throw InputError(file_, path_.empty() ? "(top level)" : path_, "must be an object");
}

std::string JsonObject::fieldPath(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

ValueSource JsonObject::source(const std::string& key) const {
  const std::string field = fieldPath(key);
  if (flags_) {
    auto it = flags_->find(field);
    if (it != flags_->end()) return {it->second, ""};
  }
  return {file_, field};
}

void JsonObject::fail(const std::string& key, const std::string& what) const {
  const ValueSource src = source(key);
  throw InputError(src.file, src.field, what);
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

void checkRange(float value, NumberRange range, const std::string& file, const std::string& field) {
  if (value >= range.lo && value <= range.hi) return;
  std::ostringstream s;
  s << "value " << value << " is outside [" << range.lo << ", " << range.hi << "]";
  throw InputError(file, field, s.str());
}

float JsonObject::number(const std::string& key, float lo, float hi,
                         std::optional<float> fallback) {
  const float v = number(key, fallback);
  const ValueSource src = source(key);
  checkRange(v, {lo, hi}, src.file, src.field);
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

std::vector<std::string> JsonObject::keys() {
  std::vector<std::string> out;
  for (auto it = value_.begin(); it != value_.end(); ++it) {
    used_.insert(it.key());
    out.push_back(it.key());
  }
  return out;
}

std::string JsonObject::filePath(const std::string& key) {
  namespace fs = std::filesystem;
  const fs::path p(string(key));
  if (p.is_absolute()) return p.lexically_normal().string();
  return (fs::path(file_).parent_path() / p).lexically_normal().string();
}

JsonObject JsonObject::object(const std::string& key) {
  return JsonObject(lookup(key), file_, fieldPath(key), flags_);
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

Transform parseTransform(JsonObject& parent, const std::string& key) {
  if (!parent.has(key)) return Transform();
  JsonObject t = parent.object(key);
  Transform xf;
  if (t.has("matrix")) {
    const std::vector<nlohmann::json> m = t.array("matrix", true);
    if (m.size() != 16) t.fail("matrix", "expected 16 numbers (row-major)");
    for (int i = 0; i < 16; ++i) {
      if (!m[static_cast<size_t>(i)].is_number()) t.fail("matrix", "expected 16 numbers");
      xf.m[i / 4][i % 4] = m[static_cast<size_t>(i)].get<float>();
    }
    if (xf.m[3][0] != 0 || xf.m[3][1] != 0 || xf.m[3][2] != 0 || xf.m[3][3] != 1)
      t.fail("matrix", "the last row must be [0, 0, 0, 1] (affine transforms only)");
  } else {
    Vec3 s(1.0f);
    if (t.has("scale")) {
      const nlohmann::json& sv = t.raw("scale");
      s = sv.is_number() ? Vec3(sv.get<float>()) : t.vec3("scale");
    }
    Transform r;
    if (t.has("rotate")) {
      JsonObject rot = t.object("rotate");
      const Vec3 axis = rot.vec3("axis");
      if (length(axis) == 0.0f) rot.fail("axis", "must not be zero");
      r = Transform::rotate(axis, rot.number("deg"));
      rot.finish();
    }
    const Vec3 tr = t.vec3("translate", Vec3(0.0f));
    xf = Transform::translate(tr) * r * Transform::scale(s);
  }
  t.finish();
  const float det = xf.determinant3();
  if (!std::isfinite(det) || std::abs(det) < 1e-12f)
    parent.fail(key, "the transform is singular (zero scale?)");
  return xf;
}

}  // namespace lvox
