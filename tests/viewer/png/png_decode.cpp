#include "png/png_decode.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include <zlib.h>

namespace mmvk::test {
namespace {

uint32_t be32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

uint8_t paeth(int a, int b, int c) {
  const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return static_cast<uint8_t>(a);
  return static_cast<uint8_t>(pb <= pc ? b : c);
}

}  // namespace

Result<RgbImage> read_png(const std::filesystem::path& path) {
  const std::string where = "png " + path.string() + ": ";
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(where + "cannot open");
  const std::vector<uint8_t> file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  static constexpr uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (file.size() < 8 || !std::equal(kSignature, kSignature + 8, file.begin())) return make_error(where + "not a PNG");

  RgbImage image;
  uint32_t channels = 0;
  std::vector<uint8_t> compressed;
  for (std::size_t at = 8; at < file.size();) {
    if (file.size() - at < 12) return make_error(where + "truncated chunk header");
    const uint32_t length = be32(&file[at]);
    const std::string type(file.begin() + static_cast<std::ptrdiff_t>(at + 4), file.begin() + static_cast<std::ptrdiff_t>(at + 8));
    if (file.size() - at - 12 < length) return make_error(where + "chunk " + type + " runs past the end");
    const uint8_t* data = &file[at + 8];
    if (type == "IHDR") {
      if (length < 13) return make_error(where + "short IHDR");
      image.width = be32(data), image.height = be32(data + 4);
      const uint8_t depth = data[8], colour = data[9], interlace = data[12];
      if (depth != 8 || (colour != 2 && colour != 6) || interlace != 0) {
        return make_error(where + "unsupported (bit depth " + std::to_string(depth) + ", colour type " +
                          std::to_string(colour) + ", interlace " + std::to_string(interlace) + ")");
      }
      channels = colour == 6 ? 4 : 3;
    } else if (type == "IDAT") {
      compressed.insert(compressed.end(), data, data + length);
    } else if (type == "IEND") {
      break;
    }
    at += 12 + std::size_t{length};
  }
  if (channels == 0 || image.width == 0 || image.height == 0) return make_error(where + "no IHDR or an empty image");
  if (std::size_t{image.width} * image.height > (std::size_t{1} << 28)) return make_error(where + "image too large");

  const std::size_t stride = std::size_t{image.width} * channels;
  std::vector<uint8_t> raw((stride + 1) * image.height);
  uLongf raw_size = static_cast<uLongf>(raw.size());
  if (uncompress(raw.data(), &raw_size, compressed.data(), static_cast<uLong>(compressed.size())) != Z_OK ||
      raw_size != raw.size()) {
    return make_error(where + "bad or short image data");
  }
  // Undo the per-row filters in place (each row starts with its filter byte).
  std::vector<uint8_t> pixels(stride * image.height);
  for (uint32_t y = 0; y < image.height; ++y) {
    const uint8_t filter = raw[y * (stride + 1)];
    const uint8_t* src = &raw[y * (stride + 1) + 1];
    uint8_t* row = &pixels[y * stride];
    const uint8_t* up = y > 0 ? &pixels[(y - 1) * stride] : nullptr;
    for (std::size_t i = 0; i < stride; ++i) {
      const int a = i >= channels ? row[i - channels] : 0, b = up ? up[i] : 0;
      const int c = up && i >= channels ? up[i - channels] : 0;
      switch (filter) {
        case 0: row[i] = src[i]; break;
        case 1: row[i] = static_cast<uint8_t>(src[i] + a); break;
        case 2: row[i] = static_cast<uint8_t>(src[i] + b); break;
        case 3: row[i] = static_cast<uint8_t>(src[i] + (a + b) / 2); break;
        case 4: row[i] = static_cast<uint8_t>(src[i] + paeth(a, b, c)); break;
        default: return make_error(where + "unknown filter " + std::to_string(filter) + " in row " + std::to_string(y));
      }
    }
  }
  image.rgb.resize(std::size_t{image.width} * image.height * 3);
  for (std::size_t p = 0; p < std::size_t{image.width} * image.height; ++p) {
    for (int c = 0; c < 3; ++c) image.rgb[p * 3 + c] = pixels[p * channels + c];
  }
  return image;
}

}  // namespace mmvk::test
