#include "src/world/ply_validate.h"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include "src/core/error.h"

namespace lvox {
namespace {

enum class Format { kAscii, kBinaryLittle, kBinaryBig };

struct ScalarType {
  int size = 0;  // bytes in a binary file
  bool integral = true;
  bool isSigned = true;
  double lo = 0.0, hi = 0.0;  // range of an integral type; ascii values are checked against it
};

bool parseScalarType(std::string_view name, ScalarType& out) {
  struct Entry {
    std::string_view name, alias;
    ScalarType type;
  };
  static constexpr Entry kTypes[] = {
      {"char", "int8", {1, true, true, -128.0, 127.0}},
      {"uchar", "uint8", {1, true, false, 0.0, 255.0}},
      {"short", "int16", {2, true, true, -32768.0, 32767.0}},
      {"ushort", "uint16", {2, true, false, 0.0, 65535.0}},
      {"int", "int32", {4, true, true, -2147483648.0, 2147483647.0}},
      {"uint", "uint32", {4, true, false, 0.0, 4294967295.0}},
      {"float", "float32", {4, false, true, 0.0, 0.0}},
      {"double", "float64", {8, false, true, 0.0, 0.0}},
  };
  for (const Entry& e : kTypes)
    if (name == e.name || name == e.alias) {
      out = e.type;
      return true;
    }
  return false;
}

struct Property {
  std::string name;
  bool list = false;
  ScalarType count, item;  // count: the length prefix of a list
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
};

// Whitespace-separated words of one line.
class Words {
 public:
  explicit Words(std::string_view line) : rest_(line) {}
  std::string_view next() {
    const size_t start = rest_.find_first_not_of(" \t\r");
    if (start == std::string_view::npos) {
      rest_ = {};
      return {};
    }
    rest_.remove_prefix(start);
    const size_t end = std::min(rest_.find_first_of(" \t\r"), rest_.size());
    const std::string_view word = rest_.substr(0, end);
    rest_.remove_prefix(end);
    return word;
  }
  bool empty() const { return rest_.find_first_not_of(" \t\r") == std::string_view::npos; }

 private:
  std::string_view rest_;
};

std::string shortText(std::string_view s) {
  std::string out(s.substr(0, 40));
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
  return out;
}

class Validator {
 public:
  Validator(std::string_view bytes, const std::string& path, const std::string& field)
      : bytes_(bytes), path_(path), field_(field) {}

  PlySummary run() {
    parseHeader();
    boundCounts();
    if (format_ == Format::kAscii)
      walkAscii();
    else
      walkBinary();
    return summary_;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(path_, field_, "malformed PLY: " + why);
  }

  // The next line from pos_ without its end of line; false at the end of the bytes.
  bool nextLine(std::string_view& line) {
    if (pos_ >= bytes_.size()) return false;
    const size_t nl = std::min(bytes_.find('\n', pos_), bytes_.size());
    line = bytes_.substr(pos_, nl - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = nl + 1;
    ++lineNumber_;
    return true;
  }

  void parseHeader() {
    std::string_view line;
    if (!nextLine(line) || line != "ply") fail("missing 'ply' magic line");
    bool format = false;
    while (nextLine(line)) {
      // Assimp splits lines at '\r' too; a header that both parsers read alike has no
      // control characters inside its lines.
      for (char c : line)
        if (static_cast<unsigned char>(c) < 0x20 && c != '\t')
          fail("a control character in header line " + std::to_string(lineNumber_));
      Words words(line);
      const std::string_view keyword = words.next();
      if (keyword == "end_header") {
        if (!format) fail("no format line");
        if (!hasVertexElement_) fail("no vertex element");
        for (const Element& e : elements_) checkMeshElement(e);
        bodyOffset_ = std::min(pos_, bytes_.size());
        return;
      }
      if (keyword == "format") {
        if (format) fail("a second format line (line " + std::to_string(lineNumber_) + ")");
        parseFormat(words.next());
        format = true;
      } else if (keyword == "element") {
        parseElement(words);
      } else if (keyword == "property") {
        parseProperty(words);
      } else if (keyword != "comment" && keyword != "obj_info") {
        fail("unexpected header line " + std::to_string(lineNumber_) + ": '" + shortText(line) +
             "'");
      }
    }
    fail("no end_header");
  }

  void parseFormat(std::string_view kind) {
    if (kind == "ascii")
      format_ = Format::kAscii;
    else if (kind == "binary_little_endian")
      format_ = Format::kBinaryLittle;
    else if (kind == "binary_big_endian")
      format_ = Format::kBinaryBig;
    else
      fail("unknown format '" + shortText(kind) + "' on line " + std::to_string(lineNumber_));
  }

  void parseElement(Words& words) {
    Element e;
    e.name = std::string(words.next());
    const std::string_view count = words.next();
    const auto [end, ec] = std::from_chars(count.data(), count.data() + count.size(), e.count);
    if (e.name.empty() || ec != std::errc() || end != count.data() + count.size() || !words.empty())
      fail("bad element line " + std::to_string(lineNumber_));
    for (const Element& other : elements_)
      if (other.name == e.name) fail("two elements named '" + shortText(e.name) + "'");
    if (e.name == "vertex") {
      hasVertexElement_ = true;
      summary_.vertices = e.count;
    }
    if (e.name == "face") summary_.faces = e.count;
    elements_.push_back(std::move(e));
  }

  void parseProperty(Words& words) {
    const std::string where = " on line " + std::to_string(lineNumber_);
    if (elements_.empty()) fail("a property before any element" + where);
    Property p;
    std::string_view type = words.next();
    if (type == "list") {
      p.list = true;
      if (!parseScalarType(words.next(), p.count) || !p.count.integral)
        fail("a list length must have an integer type" + where);
      type = words.next();
    }
    if (!parseScalarType(type, p.item))
      fail("unknown property type '" + shortText(type) + "'" + where);
    p.name = std::string(words.next());
    if (p.name.empty() || !words.empty()) fail("bad property line" + where.substr(3));
    if (indexBounds(elements_.back(), p) && !p.item.integral)
      fail("vertex indices must have an integer type" + where);
    elements_.back().properties.push_back(std::move(p));
  }

  // Assimp reads faces through their one index list and has crashed on faces without one
  // (found by fuzzing): faces and strips have exactly one list, the indices, and vertices
  // none. Other elements are skipped by assimp and only need to be well-formed.
  void checkMeshElement(const Element& e) const {
    const bool faces = e.name == "face" || e.name == "tristrips";
    if (!faces && e.name != "vertex") return;
    int lists = 0, indexLists = 0;
    for (const Property& p : e.properties) {
      lists += p.list;
      indexLists += indexBounds(e, p);
    }
    if (!faces && lists > 0) fail("the vertex element has a list property");
    if (faces && e.count > 0 && (indexLists != 1 || lists != 1))
      fail("element '" + e.name + "' needs exactly one list property, vertex_indices");
  }

  // Range [lo, hi] of the values of an index list; false for any other property. Strips
  // may use -1 to restart a strip.
  bool indexBounds(const Element& e, const Property& p, double* lo = nullptr,
                   double* hi = nullptr) const {
    if (!p.list || (p.name != "vertex_indices" && p.name != "vertex_index")) return false;
    if (e.name != "face" && e.name != "tristrips") return false;
    if (lo) *lo = e.name == "tristrips" ? -1.0 : 0.0;
    if (hi) *hi = static_cast<double>(summary_.vertices) - 1.0;
    return true;
  }

  // Every instance takes at least a few bytes (binary: its scalars and list lengths; ascii:
  // one character and a separator per value), so a count the rest of the file cannot hold
  // is refused before anything is read.
  void boundCounts() const {
    const uint64_t body = bytes_.size() - bodyOffset_;
    for (const Element& e : elements_) {
      if (e.count == 0) continue;
      if (e.properties.empty()) fail("element '" + shortText(e.name) + "' has no properties");
      uint64_t minBytes = 0;
      for (const Property& p : e.properties)
        minBytes += format_ == Format::kAscii ? 2 : (p.list ? p.count.size : p.item.size);
      if (e.count > (body + 1) / minBytes)
        fail("element '" + shortText(e.name) + "' declares " + std::to_string(e.count) +
             " instances, more than the " + std::to_string(body) +
             " bytes after the header can hold");
    }
  }

  // ---- binary ----

  double readBinary(const ScalarType& t, const Element& e) {
    const auto size = static_cast<size_t>(t.size);
    if (bytes_.size() - pos_ < size)
      fail("the data ends inside element '" + shortText(e.name) + "' (truncated?)");
    unsigned char b[8];
    std::memcpy(b, bytes_.data() + pos_, size);
    pos_ += size;
    const bool little = format_ == Format::kBinaryLittle;
    if (little != (std::endian::native == std::endian::little)) std::reverse(b, b + size);
    if (!t.integral) {
      if (size == 4) return static_cast<double>(std::bit_cast<float>(load<uint32_t>(b)));
      return std::bit_cast<double>(load<uint64_t>(b));
    }
    switch (size) {
      case 1:
        return t.isSigned ? static_cast<double>(static_cast<int8_t>(b[0])) : b[0];
      case 2: {
        const uint16_t v = load<uint16_t>(b);
        return t.isSigned ? static_cast<double>(static_cast<int16_t>(v)) : v;
      }
      default: {
        const uint32_t v = load<uint32_t>(b);
        return t.isSigned ? static_cast<double>(static_cast<int32_t>(v)) : v;
      }
    }
  }

  template <class T>
  static T load(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
  }

  void walkBinary() {
    pos_ = bodyOffset_;
    // Assimp skips a line end at the start of a binary body and reads the data one byte
    // late (found by fuzzing: valid faces read shifted, then assimp aborts): refused, since
    // assimp would misread it even where it does not crash.
    if (pos_ < bytes_.size() && (bytes_[pos_] == '\n' || bytes_[pos_] == '\r'))
      fail(
          "the binary data starts with a line-end byte, which assimp (lvox's PLY reader) "
          "skips, reading everything one byte late; write the file again");
    for (const Element& e : elements_)
      for (uint64_t i = 0; i < e.count; ++i)
        for (const Property& p : e.properties) {
          if (!p.list) {
            skipBinary(p.item.size, e);
            continue;
          }
          const double n = readBinary(p.count, e);
          double lo, hi;
          const bool indices = indexBounds(e, p, &lo, &hi);
          checkListLength(n, e, indices, i);
          if (indices) {
            for (double k = 0; k < n; ++k) checkIndex(readBinary(p.item, e), lo, hi, e, i);
          } else {
            const double bytes = n * p.item.size;
            if (bytes > static_cast<double>(bytes_.size() - pos_))
              fail("the data ends inside element '" + shortText(e.name) + "' (truncated?)");
            skipBinary(static_cast<size_t>(bytes), e);
          }
        }
  }

  void skipBinary(size_t n, const Element& e) {
    if (bytes_.size() - pos_ < n)
      fail("the data ends inside element '" + shortText(e.name) + "' (truncated?)");
    pos_ += n;
  }

  // Assimp's triangulation aborts on a face with no vertices; one or two make no
  // triangle either, so index lists need at least three.
  void checkListLength(double n, const Element& e, bool indices, uint64_t instance) const {
    if (n < 0.0) fail("a list of element '" + shortText(e.name) + "' has a negative length");
    if (indices && n < 3.0)
      fail(shortText(e.name) + " " + std::to_string(instance) + " has " +
           std::to_string(static_cast<int>(n)) + " vertices; at least 3 are needed");
  }

  void checkIndex(double v, double lo, double hi, const Element& e, uint64_t instance) const {
    if (v < lo || v > hi)
      fail(shortText(e.name) + " " + std::to_string(instance) + " refers to vertex " +
           std::to_string(static_cast<long long>(v)) + " but the file has " +
           std::to_string(summary_.vertices));
  }

  // ---- ascii: one instance per line ----

  double parseAscii(std::string_view word, const ScalarType& t) const {
    const std::string where = " on line " + std::to_string(lineNumber_);
    if (word.empty()) fail("too few values" + where);
    if (word.size() > 1 && word[0] == '+') word.remove_prefix(1);
    const char* first = word.data();
    const char* last = word.data() + word.size();
    if (t.integral) {
      long long v = 0;
      const auto [end, ec] = std::from_chars(first, last, v);
      const auto d = static_cast<double>(v);
      if (ec != std::errc() || end != last || d < t.lo || d > t.hi)
        fail("'" + shortText(word) + "' is not a valid integer of its type" + where);
      return d;
    }
    double v = 0.0;
    const auto [end, ec] = std::from_chars(first, last, v);
    // Out-of-range values (ec == result_out_of_range) are a number all the same.
    if ((ec != std::errc() && ec != std::errc::result_out_of_range) || end != last)
      fail("'" + shortText(word) + "' is not a number" + where);
    return v;
  }

  void walkAscii() {
    pos_ = bodyOffset_;
    std::string_view line;
    for (const Element& e : elements_)
      for (uint64_t i = 0; i < e.count; ++i) {
        if (!nextLine(line))
          fail("element '" + shortText(e.name) + "' ends after " + std::to_string(i) + " of " +
               std::to_string(e.count) + " instances (truncated?)");
        Words words(line);
        for (const Property& p : e.properties) {
          if (!p.list) {
            parseAscii(words.next(), p.item);
            continue;
          }
          const double n = parseAscii(words.next(), p.count);
          double lo = 0.0, hi = 0.0;
          const bool indices = indexBounds(e, p, &lo, &hi);
          checkListLength(n, e, indices, i);
          for (double k = 0; k < n; ++k) {
            const double v = parseAscii(words.next(), p.item);
            if (indices) checkIndex(v, lo, hi, e, i);
          }
        }
        if (!words.empty()) fail("extra values on line " + std::to_string(lineNumber_));
      }
  }

  std::string_view bytes_;
  const std::string& path_;
  const std::string& field_;
  size_t pos_ = 0;
  size_t bodyOffset_ = 0;
  int64_t lineNumber_ = 0;
  Format format_ = Format::kAscii;
  std::vector<Element> elements_;
  bool hasVertexElement_ = false;
  PlySummary summary_;
};

}  // namespace

PlySummary validatePlyBytes(std::string_view bytes, const std::string& path,
                            const std::string& field) {
  return Validator(bytes, path, field).run();
}

PlySummary validatePly(const std::string& path, const std::string& field) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, field, std::string("cannot open: ") + std::strerror(errno));
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(path, field, "read error");
  return validatePlyBytes(bytes, path, field);
}

}  // namespace lvox
