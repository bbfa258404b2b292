// A small radix-2 FFT of real input, for the phase channel's dominant
// frequency: sizes are a few hundred samples, so a plain iterative
// Cooley-Tukey with precomputed twiddles is enough and keeps the library
// free of an FFT dependency.
#pragma once

#include <complex>
#include <cstddef>
#include <span>
#include <vector>

namespace mmvk::detail {

class RealFft {
 public:
  // `size` must be a power of two >= 2.
  explicit RealFft(std::size_t size);

  std::size_t size() const { return size_; }

  // The spectrum of `input` (at most size() samples, zero-padded to size()):
  // out[k] = sum_m input[m] exp(-2 pi i k m / size) for k = 0 .. size / 2.
  // `out` is resized to size() / 2 + 1; no allocation once it has that size.
  void forward(std::span<const double> input, std::vector<std::complex<double>>& out);

 private:
  std::size_t size_;
  std::vector<std::complex<double>> twiddles_;  // exp(-2 pi i k / size), k < size / 2
  std::vector<std::size_t> reversed_;           // bit-reversed index of each sample
  std::vector<std::complex<double>> work_;
};

// The smallest power of two >= n (n >= 1).
std::size_t next_power_of_two(std::size_t n);

}  // namespace mmvk::detail
