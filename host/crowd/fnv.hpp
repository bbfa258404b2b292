// FNV-1a, 64 bit: the host's digest for cache keys and the chosen-frames
// hash (stable across platforms, so equal runs give equal digests).
#pragma once

#include <cstdint>
#include <string_view>

namespace mmvk::crowd {

class Fnv1a {
 public:
  void add_bytes(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) state_ = (state_ ^ bytes[i]) * 0x100000001b3ull;
  }
  // Little-endian bytes of a 32-bit value, whatever the host's byte order.
  void add_u32(std::uint32_t value) {
    const unsigned char bytes[4] = {static_cast<unsigned char>(value), static_cast<unsigned char>(value >> 8),
                                    static_cast<unsigned char>(value >> 16), static_cast<unsigned char>(value >> 24)};
    add_bytes(bytes, 4);
  }
  void add_text(std::string_view text) {
    add_u32(static_cast<std::uint32_t>(text.size()));
    add_bytes(text.data(), text.size());
  }
  std::uint64_t digest() const { return state_; }

 private:
  std::uint64_t state_ = 0xcbf29ce484222325ull;
};

}  // namespace mmvk::crowd
