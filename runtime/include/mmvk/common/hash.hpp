// A 64-bit FNV-1a digest: database identity, file checksums, and the hosts'
// cache keys and run digests. Not cryptographic; it catches truncation, bit
// flips and mismatched files, and gives the same digest on every platform
// for the same bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <string_view>

namespace mmvk {

class Hasher {
 public:
  void add_bytes(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
      state_ = (state_ ^ bytes[i]) * 0x100000001b3ull;
    }
  }
  // The value's bytes in memory (the host's byte order).
  template <class T>
  void add(const T& value) { add_bytes(&value, sizeof(T)); }
  template <class T>
  void add_span(std::span<const T> values) { add_bytes(values.data(), values.size_bytes()); }
  // Little-endian bytes of a 32-bit value, whatever the host's byte order.
  void add_u32(std::uint32_t value) {
    const unsigned char bytes[4] = {static_cast<unsigned char>(value), static_cast<unsigned char>(value >> 8),
                                    static_cast<unsigned char>(value >> 16), static_cast<unsigned char>(value >> 24)};
    add_bytes(bytes, 4);
  }
  // The text's length (add_u32), then its bytes: "ab" + "c" and "a" + "bc"
  // give different digests.
  void add_text(std::string_view text) {
    add_u32(static_cast<std::uint32_t>(text.size()));
    add_bytes(text.data(), text.size());
  }
  std::uint64_t digest() const { return state_; }

 private:
  std::uint64_t state_ = 0xcbf29ce484222325ull;
};

// How every mmvk tool prints a digest: "0x" and 16 hex digits (a string in
// JSON too, where a 64-bit integer is not exact in every reader's doubles).
inline std::string hash_hex(std::uint64_t digest) {
  char text[19];
  std::snprintf(text, sizeof(text), "0x%016llx", static_cast<unsigned long long>(digest));
  return text;
}

}  // namespace mmvk
