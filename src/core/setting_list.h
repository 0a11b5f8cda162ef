#pragma once
// A library's settings as (scene field, value) pairs, written into every image's header and
// report: what two renders must share to be parts of one image (`lvox merge` compares them).
// Each library lists its own settings beside their parser.
#include <charconv>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace lvox {

class SettingList {
 public:
  void add(const std::string& field, std::string_view value) {
    items_.emplace_back(field, std::string(value));
  }
  // Shortest text that reads back to the same float.
  void add(const std::string& field, float value) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, value);
    items_.emplace_back(field, std::string(buf, r.ptr));
  }
  void add(const std::string& field, int value) {
    items_.emplace_back(field, std::to_string(value));
  }
  void add(const std::string& field, uint32_t value) {
    items_.emplace_back(field, std::to_string(value));
  }
  void append(const SettingList& other) {
    items_.insert(items_.end(), other.items_.begin(), other.items_.end());
  }
  const std::vector<std::pair<std::string, std::string>>& items() const { return items_; }

 private:
  std::vector<std::pair<std::string, std::string>> items_;
};

}  // namespace lvox
