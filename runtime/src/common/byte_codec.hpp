// Little-endian byte encoding for mmvk's binary formats (the .mmdb file,
// the scene import's child-process result): a Writer that appends, and a
// Reader that checks every read against what is left, so that sizes read
// from untrusted bytes are checked before they are used.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "mmvk/common/file_io.hpp"

namespace mmvk::detail {

// Little-endian encoding independent of the host's byte order.
class Writer {
 public:
  void u8(std::uint8_t v) { bytes_.push_back(static_cast<char>(v)); }
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes_.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  }
  void u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) bytes_.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  }
  void f32(float v) { u32(std::bit_cast<std::uint32_t>(v)); }
  void i16(std::int16_t v) {
    const auto bits = static_cast<std::uint16_t>(v);
    bytes_.push_back(static_cast<char>(bits & 0xFF));
    bytes_.push_back(static_cast<char>(bits >> 8));
  }
  void str(std::string_view s) {
    u32(static_cast<std::uint32_t>(s.size()));
    bytes_.append(s);
  }
  void raw(std::string_view s) { bytes_.append(s); }
  // Bulk form of f32 for the feature matrix (the bulk of the file).
  void f32_array(std::span<const float> values) { append_f32_le(bytes_, values); }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

// Bounds-checked reads: every size read from the file is compared with what
// is left before it is used.
class Reader {
 public:
  Reader(std::string_view bytes, std::size_t start, std::size_t end) : bytes_(bytes), pos_(start), end_(end) {}

  std::size_t left() const { return end_ - pos_; }
  std::size_t position() const { return pos_; }

  bool u8(std::uint8_t& v) {
    if (left() < 1) return false;
    v = static_cast<std::uint8_t>(bytes_[pos_++]);
    return true;
  }
  bool u32(std::uint32_t& v) { return little_endian(v); }
  bool u64(std::uint64_t& v) { return little_endian(v); }
  bool f32(float& v) {
    std::uint32_t bits = 0;
    if (!u32(bits)) return false;
    v = std::bit_cast<float>(bits);
    return true;
  }
  bool i16(std::int16_t& v) {
    if (left() < 2) return false;
    const auto lo = static_cast<std::uint8_t>(bytes_[pos_]);
    const auto hi = static_cast<std::uint8_t>(bytes_[pos_ + 1]);
    v = static_cast<std::int16_t>(static_cast<std::uint16_t>(lo | (hi << 8)));
    pos_ += 2;
    return true;
  }
  // Precondition: 4 * values.size() <= left().
  void f32_array(std::span<float> values) {
    decode_f32_le(bytes_.substr(pos_), values);
    pos_ += values.size_bytes();
  }
  bool str(std::string& s) {
    std::uint32_t size = 0;
    if (!u32(size) || size > left()) return false;
    s.assign(bytes_.data() + pos_, size);
    pos_ += size;
    return true;
  }

 private:
  template <class Unsigned>
  bool little_endian(Unsigned& v) {
    if (left() < sizeof(Unsigned)) return false;
    v = 0;
    for (std::size_t i = 0; i < sizeof(Unsigned); ++i) {
      v |= Unsigned{static_cast<std::uint8_t>(bytes_[pos_ + i])} << (8 * i);
    }
    pos_ += sizeof(Unsigned);
    return true;
  }

  std::string_view bytes_;
  std::size_t pos_;
  std::size_t end_;
};

}  // namespace mmvk::detail
