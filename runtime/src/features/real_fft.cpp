#include "features/real_fft.hpp"

#include <algorithm>
#include <cassert>
#include <numbers>

namespace mmvk::detail {

std::size_t next_power_of_two(std::size_t n) {
  std::size_t p = 1;
  while (p < n) p <<= 1;
  return p;
}

RealFft::RealFft(std::size_t size) : size_(size), twiddles_(size / 2), reversed_(size), work_(size) {
  assert(size >= 2 && (size & (size - 1)) == 0);
  for (std::size_t k = 0; k < size / 2; ++k) {
    const double angle = -2.0 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(size);
    twiddles_[k] = std::polar(1.0, angle);
  }
  std::size_t bits = 0;
  while ((std::size_t{1} << bits) < size) ++bits;
  for (std::size_t i = 0; i < size; ++i) {
    std::size_t r = 0;
    for (std::size_t b = 0; b < bits; ++b) r |= ((i >> b) & 1u) << (bits - 1 - b);
    reversed_[i] = r;
  }
}

void RealFft::forward(std::span<const double> input, std::vector<std::complex<double>>& out) {
  assert(input.size() <= size_);
  for (std::size_t i = 0; i < size_; ++i) {
    const std::size_t source = reversed_[i];
    work_[i] = source < input.size() ? std::complex<double>(input[source], 0.0) : std::complex<double>(0.0, 0.0);
  }
  for (std::size_t half = 1; half < size_; half <<= 1) {
    const std::size_t stride = size_ / (2 * half);
    for (std::size_t start = 0; start < size_; start += 2 * half) {
      for (std::size_t k = 0; k < half; ++k) {
        const std::complex<double> odd = twiddles_[k * stride] * work_[start + k + half];
        const std::complex<double> even = work_[start + k];
        work_[start + k] = even + odd;
        work_[start + k + half] = even - odd;
      }
    }
  }
  out.resize(size_ / 2 + 1);
  std::copy_n(work_.begin(), size_ / 2 + 1, out.begin());
}

}  // namespace mmvk::detail
