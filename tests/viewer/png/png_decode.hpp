// A small PNG reader for the viewer test's screenshots: 8-bit RGB or RGBA,
// not interlaced (what Chromium writes). Debian's python3 has no PIL, so
// the test reads the pixels itself.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "mmvk/common/status.hpp"

namespace mmvk::test {

struct RgbImage {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<uint8_t> rgb;  // [height x width x 3], rows top to bottom

  const uint8_t* pixel(uint32_t x, uint32_t y) const { return &rgb[(std::size_t{y} * width + x) * 3]; }
};

// Errors name the file and what is wrong (not a PNG, a truncated chunk, an
// unsupported colour type or bit depth, interlacing, bad compressed data).
Result<RgbImage> read_png(const std::filesystem::path& path);

}  // namespace mmvk::test
