#include "pipeline_cache_blob.hpp"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

namespace mmvk::vulkan::detail {

namespace {

// The header's fields are little-endian whatever the host's byte order.
std::uint32_t read_u32_le(std::span<const std::byte> bytes, std::size_t at) {
  std::uint32_t value = 0;
  for (std::size_t b = 0; b < 4; ++b) value |= std::uint32_t(bytes[at + b]) << (8 * b);
  return value;
}

std::string hex(std::uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof(text), "0x%x", value);
  return text;
}

}  // namespace

Status check_pipeline_cache_blob(std::span<const std::byte> blob, const VkPhysicalDeviceProperties& device) {
  constexpr std::size_t kHeaderBytes = 16 + VK_UUID_SIZE;
  if (blob.size() < kHeaderBytes) {
    return make_error("pipeline cache: " + std::to_string(blob.size()) + " bytes is shorter than its " +
                      std::to_string(kHeaderBytes) + "-byte header");
  }
  const std::uint32_t header_size = read_u32_le(blob, 0);
  const std::uint32_t version = read_u32_le(blob, 4);
  const std::uint32_t vendor = read_u32_le(blob, 8);
  const std::uint32_t device_id = read_u32_le(blob, 12);
  if (header_size < kHeaderBytes || header_size > blob.size()) {
    return make_error("pipeline cache: header size " + std::to_string(header_size) + " is not in [" +
                      std::to_string(kHeaderBytes) + ", " + std::to_string(blob.size()) + "]");
  }
  if (version != VK_PIPELINE_CACHE_HEADER_VERSION_ONE) {
    return make_error("pipeline cache: header version " + std::to_string(version) + ", expected 1");
  }
  if (vendor != device.vendorID || device_id != device.deviceID) {
    return make_error("pipeline cache: made for vendor " + hex(vendor) + " device " + hex(device_id) + ", this is " +
                      hex(device.vendorID) + " " + hex(device.deviceID) + " (" + device.deviceName + ")");
  }
  if (std::memcmp(blob.data() + 16, device.pipelineCacheUUID, VK_UUID_SIZE) != 0) {
    return make_error("pipeline cache: made by another driver build of " + std::string(device.deviceName) +
                      " (pipelineCacheUUID differs)");
  }
  return {};
}

}  // namespace mmvk::vulkan::detail
