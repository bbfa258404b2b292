// A 64-bit FNV-1a digest: used for database identity and file checksums.
// Not cryptographic; it catches truncation, bit flips and mismatched files.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace mmvk::detail {

class Hasher {
 public:
  void add_bytes(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
      state_ = (state_ ^ bytes[i]) * 0x100000001b3ull;
    }
  }
  template <class T>
  void add(const T& value) { add_bytes(&value, sizeof(T)); }
  template <class T>
  void add_span(std::span<const T> values) { add_bytes(values.data(), values.size_bytes()); }
  std::uint64_t digest() const { return state_; }

 private:
  std::uint64_t state_ = 0xcbf29ce484222325ull;
};

}  // namespace mmvk::detail
