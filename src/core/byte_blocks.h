#pragma once
// Plain arrays as bytes, for what ranks send each other (Collective::allgather,
// broadcast): a block is a magic number, a layout number, then values and arrays of
// trivially copyable types, each array as its element count, its element size and its
// bytes. No pointers, no padding games: the receiver reads the same fields in the same
// order, and every size is checked on receipt, so a block of another layout or build (a
// different sizeof, a truncated transfer) is a clear error naming where it came from,
// never a crash or silent garbage. Change the layout number when the fields change.
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace lvox {

inline constexpr uint32_t kByteBlockMagic = 0x4c565842u;  // "LVXB"

// What a block may hold: values whose bytes are the whole value (numbers, and structs of
// numbers such as Imath's vectors, which are standard-layout but declare copy constructors,
// so not formally trivially copyable), never pointers.
template <class T>
concept PlainData =
    std::is_standard_layout_v<T> && std::is_trivially_destructible_v<T> && !std::is_pointer_v<T> &&
    !std::is_member_pointer_v<T>;

class ByteBlockWriter {
 public:
  explicit ByteBlockWriter(uint32_t layout) {
    value(kByteBlockMagic);
    value(layout);
  }
  template <class T>
  void value(const T& v) {
    static_assert(PlainData<T>);
    bytes_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  template <class T>
  void array(const std::vector<T>& v) {
    static_assert(PlainData<T>);
    value(static_cast<uint64_t>(v.size()));
    value(static_cast<uint32_t>(sizeof(T)));
    bytes_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  std::string take() { return std::move(bytes_); }

 private:
  std::string bytes_;
};

class ByteBlockReader {
 public:
  // `from` names the sender in errors ("rank 1").
  ByteBlockReader(std::string_view bytes, uint32_t layout, std::string from)
      : bytes_(bytes), from_(std::move(from)) {
    if (value<uint32_t>() != kByteBlockMagic) fail("not a block of lvox arrays");
    const auto got = value<uint32_t>();
    if (got != layout)
      fail("block layout " + std::to_string(got) + ", expected " + std::to_string(layout) +
           " (a different lvox build?)");
  }
  template <class T>
  T value() {
    static_assert(PlainData<T>);
    need(sizeof(T), "a value");
    T v;
    std::memcpy(static_cast<void*>(&v), bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  // Replaces `out` with the next array; `what` names it in errors.
  template <class T>
  void array(std::vector<T>& out, const char* what) {
    static_assert(PlainData<T>);
    const auto count = value<uint64_t>();
    const auto size = value<uint32_t>();
    if (size != sizeof(T))
      fail(std::string(what) + ": elements of " + std::to_string(size) + " bytes, expected " +
           std::to_string(sizeof(T)));
    if (count > (bytes_.size() - at_) / sizeof(T))
      fail(std::string(what) + ": " + std::to_string(count) + " elements announced, " +
           std::to_string(bytes_.size() - at_) + " bytes left");
    out.resize(static_cast<size_t>(count));
    std::memcpy(static_cast<void*>(out.data()), bytes_.data() + at_, out.size() * sizeof(T));
    at_ += out.size() * sizeof(T);
  }
  // Every byte was read.
  void finish() const {
    if (at_ != bytes_.size())
      fail(std::to_string(bytes_.size() - at_) + " bytes left after the last field");
  }

 private:
  void need(size_t n, const char* what) const {
    if (bytes_.size() - at_ < n)
      fail(std::string("truncated block: ") + what + " needs " + std::to_string(n) + " bytes, " +
           std::to_string(bytes_.size() - at_) + " left");
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error("the arrays received from " + from_ + ": " + what + " (" +
                             std::to_string(bytes_.size()) + " bytes)");
  }
  std::string_view bytes_;
  size_t at_ = 0;
  std::string from_;
};

}  // namespace lvox
