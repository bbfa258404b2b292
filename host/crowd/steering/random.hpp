// A small deterministic generator (SplitMix64): the same numbers for a seed on
// every compiler and platform, which std:: distributions do not promise.
#pragma once

#include <cstdint>

namespace mmvk::crowd {

class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}

  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [lo, hi), from the top 24 bits (exact in float).
  float uniform(float lo, float hi) { return lo + (hi - lo) * (float(next() >> 40) * (1.0f / 16777216.0f)); }

 private:
  std::uint64_t state_;
};

}  // namespace mmvk::crowd
