#include "mmvk/vulkan/pipeline_cache_file.hpp"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <system_error>

#include "mmvk/common/hash.hpp"
#include "mmvk/common/file_io.hpp"

namespace mmvk::vulkan {

namespace {

constexpr char kMagic[8] = {'M', 'M', 'V', 'K', 'P', 'C', 'F', '1'};
constexpr std::uint32_t kVersion = 1;
// magic, version, reserved, blob size, checksum
constexpr std::size_t kFrameBytes = sizeof(kMagic) + 4 + 4 + 8 + 8;
// Drivers' caches of mmvk's few kernels are a few MB; more is not ours.
constexpr std::uint64_t kMaxPipelineCacheBytes = std::uint64_t{256} << 20;

void append_le(std::string& out, std::uint64_t value, std::size_t bytes) {
  for (std::size_t b = 0; b < bytes; ++b) out.push_back(static_cast<char>((value >> (8 * b)) & 0xFF));
}

std::uint64_t read_le(std::string_view in, std::size_t at, std::size_t bytes) {
  std::uint64_t value = 0;
  for (std::size_t b = 0; b < bytes; ++b) value |= std::uint64_t(static_cast<unsigned char>(in[at + b])) << (8 * b);
  return value;
}

std::uint64_t checksum(const void* data, std::size_t size) {
  Hasher hasher;
  hasher.add_bytes(data, size);
  return hasher.digest();
}

}  // namespace

std::filesystem::path pipeline_cache_file(const Context& context, const std::filesystem::path& directory) {
  char name[64];
  std::snprintf(name, sizeof(name), "vulkan-%04x-%04x.pipeline-cache", context.properties().vendorID,
                context.properties().deviceID);
  return directory / name;
}

std::string encode_pipeline_cache_file(std::span<const std::byte> blob) {
  std::string bytes(kMagic, sizeof(kMagic));
  append_le(bytes, kVersion, 4);
  append_le(bytes, 0, 4);
  append_le(bytes, blob.size(), 8);
  append_le(bytes, checksum(blob.data(), blob.size()), 8);
  bytes.append(reinterpret_cast<const char*>(blob.data()), blob.size());
  return bytes;
}

Result<std::vector<std::byte>> decode_pipeline_cache_file(std::string_view bytes) {
  if (bytes.size() < kFrameBytes || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    return make_error("not an mmvk pipeline cache file (bad magic or shorter than its header)");
  }
  const std::uint64_t version = read_le(bytes, 8, 4);
  if (version != kVersion) {
    return make_error("pipeline cache file version " + std::to_string(version) + ", this mmvk reads " +
                      std::to_string(kVersion));
  }
  const std::uint64_t size = read_le(bytes, 16, 8);
  if (size != bytes.size() - kFrameBytes) {
    return make_error("truncated or padded: the header says " + std::to_string(size) + " bytes of cache, the file holds " +
                      std::to_string(bytes.size() - kFrameBytes));
  }
  const std::string_view blob = bytes.substr(kFrameBytes);
  if (read_le(bytes, 24, 8) != checksum(blob.data(), blob.size())) return make_error("checksum mismatch (damaged file)");
  std::vector<std::byte> data(blob.size());
  if (!blob.empty()) std::memcpy(data.data(), blob.data(), blob.size());  // null data() for an empty blob
  return data;
}

std::string load_pipeline_cache_file(Context& context, const std::filesystem::path& directory) {
  const std::filesystem::path path = pipeline_cache_file(context, directory);
  std::error_code error;
  if (!std::filesystem::exists(path, error)) return {};  // the first run on this device
  // A regular file only: a symlink to /dev/zero or a FIFO planted in the
  // cache folder fails at once instead of being read or blocking.
  Result<std::string> bytes = read_file(path, ReadOptions{kMaxPipelineCacheBytes, false});
  if (!bytes) return bytes.message() + "; the pipeline cache starts empty";
  Result<std::vector<std::byte>> blob = decode_pipeline_cache_file(*bytes);
  if (!blob) return path.string() + ": " + blob.message() + "; ignored, the pipeline cache starts empty";
  const Status merged = context.merge_pipeline_cache_data(*blob);
  if (!merged) return path.string() + ": " + merged.message() + "; ignored, the pipeline cache starts empty";
  return {};
}

Status save_pipeline_cache_file(const Context& context, const std::filesystem::path& directory) {
  MMVK_ASSIGN_OR_RETURN(const std::vector<std::byte> blob, context.pipeline_cache_data());
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) return make_error(directory.string() + ": cannot create the cache directory: " + error.message());
  // A cache entry: whatever stands at its name (a symlink, a device node) is
  // replaced, never written through.
  return write_file_atomically(pipeline_cache_file(context, directory), encode_pipeline_cache_file(blob),
                               OutputPolicy::CacheEntry);
}

}  // namespace mmvk::vulkan
