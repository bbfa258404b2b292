// IEEE binary16 ("half") conversions in portable code: the half-precision
// tiles are built with float_to_half (the half boxes with its directed
// forms), and the baseline kernels read them
// with half_to_float (the x86 kernels use F16C / AVX-512's vcvtph2ps, which
// converts exactly as half_to_float does: every half is a float).
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

namespace mmvk::detail {

// The largest finite half.
inline constexpr float kHalfMax = 65504.0f;

// Exact (every half value is a float).
inline float half_to_float(std::uint16_t h) {
  const std::uint32_t sign = std::uint32_t{h & 0x8000u} << 16;
  const std::uint32_t exponent = (h >> 10) & 0x1fu;
  const std::uint32_t mantissa = h & 0x3ffu;
  if (exponent == 0) {
    // Zero or subnormal: mantissa * 2^-24, exact in float.
    const float magnitude = static_cast<float>(mantissa) * 0x1p-24f;
    return sign != 0 ? -magnitude : magnitude;
  }
  if (exponent == 31) return std::bit_cast<float>(sign | 0x7f800000u | (mantissa << 13));
  return std::bit_cast<float>(sign | ((exponent + 112u) << 23) | (mantissa << 13));
}

// Round to nearest, ties to even, for finite |f| <= kHalfMax (callers keep
// other values out of the half tiles).
inline std::uint16_t float_to_half(float f) {
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(f);
  const std::uint32_t sign = (bits >> 16) & 0x8000u;
  const std::uint32_t magnitude = bits & 0x7fffffffu;
  if (magnitude < 0x38800000u) {
    // Below the smallest normal half (2^-14): a multiple of 2^-24. The
    // scaling by 2^24 is exact and nearbyint rounds ties to even (the
    // default rounding mode); 1024 is the smallest normal half's encoding.
    const float scaled = std::bit_cast<float>(magnitude) * 0x1p24f;
    return static_cast<std::uint16_t>(sign | static_cast<std::uint32_t>(std::nearbyint(scaled)));
  }
  std::uint32_t h = (magnitude >> 13) - ((127u - 15u) << 10);
  const std::uint32_t rest = magnitude & 0x1fffu;
  if (rest > 0x1000u || (rest == 0x1000u && (h & 1u) != 0)) ++h;  // a carry moves to the next binade, as it should
  return static_cast<std::uint16_t>(sign | h);
}

// Directed rounding, for boxes that must hold their float box (a box's low
// ends rounded down, its high ends up): the largest half <= f, for any f
// but NaN (below -kHalfMax: -inf; above it: kHalfMax).
inline std::uint16_t float_to_half_down(float f) {
  if (f < -kHalfMax) return 0xfc00u;
  if (f > kHalfMax) return 0x7bffu;
  const std::uint16_t h = float_to_half(f);
  if (!(half_to_float(h) > f)) return h;
  // One half toward -inf: +0 goes to the negative subnormal nearest 0, a
  // positive half down in magnitude, a negative one up.
  if (h == 0) return 0x8001u;
  return static_cast<std::uint16_t>((h & 0x8000u) != 0 ? h + 1u : h - 1u);
}

// The smallest half >= f, for any f but NaN: -round_down(-f).
inline std::uint16_t float_to_half_up(float f) {
  return static_cast<std::uint16_t>(float_to_half_down(-f) ^ 0x8000u);
}

}  // namespace mmvk::detail
