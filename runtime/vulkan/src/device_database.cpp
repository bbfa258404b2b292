#include "device_database.hpp"

#include <array>
#include <bit>
#include <string>
#include <vector>

#include "check.hpp"
#include "scan_rows.hpp"
#include "search_layout.hpp"

namespace mmvk::vulkan::detail {

namespace {

// Whether the device can view `texels` texels of `format` as one uniform
// texel buffer.
Status check_texel_view(const Context& context, VkFormat format, std::uint64_t texels, const char* what) {
  const VkPhysicalDeviceLimits& limits = context.properties().limits;
  if (texels > limits.maxTexelBufferElements) {
    return make_error(std::string("Vulkan: too large for this device: ") + what + " needs " +
                      std::to_string(texels) + " texels, maxTexelBufferElements is " +
                      std::to_string(limits.maxTexelBufferElements));
  }
  VkFormatProperties format_props;
  vkGetPhysicalDeviceFormatProperties(context.physical_device(), format, &format_props);
  if ((format_props.bufferFeatures & VK_FORMAT_FEATURE_UNIFORM_TEXEL_BUFFER_BIT) == 0) {
    return make_error(std::string("Vulkan: the device cannot read ") + what + " as a uniform texel buffer");
  }
  return {};
}

}  // namespace

Result<UniqueBufferView> create_texel_view(const Context& context, const Buffer& buffer, VkFormat format,
                                           std::uint32_t texel_bytes, std::uint64_t bytes, const char* what) {
  const std::uint64_t texels = bytes / texel_bytes;
  MMVK_TRY(check_texel_view(context, format, texels, what));
  VkBufferViewCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO;
  info.buffer = buffer.buffer.get();
  info.format = format;
  info.offset = 0;
  info.range = texels * texel_bytes;
  VkBufferView view = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreateBufferView(context.device(), &info, nullptr, &view));
  return UniqueBufferView(context.device(), view);
}

Result<TexelBuffer> make_texel_buffer(const Context& context, VkCommandPool pool, VkFormat format,
                                      std::uint32_t texel_bytes, std::span<const std::byte> data, const char* what,
                                      bool force_staging) {
  MMVK_TRY(check_texel_view(context, format, data.size() / texel_bytes, what));
  Result<Buffer> buffer = create_buffer(context, data.size(),
                                        VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                        MemoryUse::DeviceLocal, what);
  if (!buffer) return buffer.error();
  if (force_staging && buffer->mapped != nullptr) {
    vkUnmapMemory(context.device(), buffer->memory.get());
    buffer->mapped = nullptr;
  }
  MMVK_TRY(upload(context, pool, *buffer, data));
  TexelBuffer result;
  MMVK_ASSIGN_OR_RETURN(result.view, create_texel_view(context, *buffer, format, texel_bytes, data.size(), what));
  result.buffer = std::move(*buffer);
  return result;
}

std::uint32_t scan_row_count(const Database& database) {
  std::uint32_t rows = 0;
  for (const std::uint32_t flags : database.frame_flags()) rows += scanned_by_brute_force(flags) ? 1 : 0;
  return rows;
}

Result<DeviceDatabase> upload_database(const Context& context, VkCommandPool pool, const Database& database,
                                       bool with_scan, bool force_staging) {
  DeviceDatabase device;
  device.frame_count = database.frame_count();
  device.dims = database.dims();
  device.dim_vec4s = (device.dims + 3) / 4;
  const std::size_t frames = device.frame_count;
  const std::size_t padded = std::size_t{device.dim_vec4s} * 4;

  // The brute force's scan rows, and the host's map from frames to them.
  const std::vector<std::uint32_t> scan = with_scan ? scan_frame_list(database) : std::vector<std::uint32_t>{};
  if (with_scan) device.scan_rows_before = scan_rows_before(database);

  // Host copies in the kernels' layouts; creation-time only.
  {
    // Rows interleaved by kRowGroup (search_layout.hpp), the last group
    // padded with zero rows; in brute-force mode the scan rows come first
    // (scan_rows.hpp: feature_row()).
    const std::size_t groups = (frames + kRowGroup - 1) / kRowGroup;
    std::vector<float> features(groups * kRowGroup * padded, 0.0f);
    const std::span<const float> source = database.features();
    for (std::uint32_t f = 0; f < frames; ++f) {
      const std::uint32_t row = feature_row(device.scan_rows_before, f);
      for (std::size_t d = 0; d < device.dims; ++d) {
        features[feature_texel(row, static_cast<std::uint32_t>(d / 4), device.dim_vec4s) * 4 + d % 4] =
            source[std::size_t{f} * device.dims + d];
      }
    }
    Result<TexelBuffer> buffer = make_texel_buffer(context, pool, VK_FORMAT_R32G32B32A32_SFLOAT, 16, bytes_of(features),
                                                   "the feature matrix", force_staging);
    if (!buffer) return buffer.error();
    device.features = std::move(*buffer);
  }
  {
    std::vector<std::array<std::uint32_t, 4>> meta(frames);
    for (std::size_t f = 0; f < frames; ++f) {
      const TagMask tags = database.frame_tags()[f];
      meta[f] = {database.frame_flags()[f], static_cast<std::uint32_t>(tags), static_cast<std::uint32_t>(tags >> 32),
                 database.frame_clip()[f]};
    }
    Result<TexelBuffer> buffer =
        make_texel_buffer(context, pool, VK_FORMAT_R32G32B32A32_UINT, 16, bytes_of(meta), "the frame metadata",
                          force_staging);
    if (!buffer) return buffer.error();
    device.frame_meta = std::move(*buffer);
  }
  {
    std::vector<std::array<float, 2>> cost(frames);
    for (std::size_t f = 0; f < frames; ++f) cost[f] = {database.frame_multiplier()[f], database.frame_bias()[f]};
    Result<TexelBuffer> buffer =
        make_texel_buffer(context, pool, VK_FORMAT_R32G32_SFLOAT, 8, bytes_of(cost), "the frame cost terms",
                          force_staging);
    if (!buffer) return buffer.error();
    device.frame_cost = std::move(*buffer);
  }
  {
    device.scan_rows = static_cast<std::uint32_t>(scan.size());
    // A buffer is never empty; with no scan rows the scan reads none of it.
    const std::vector<std::uint32_t> scan_texels = scan.empty() ? std::vector<std::uint32_t>{0} : scan;
    Result<TexelBuffer> buffer = make_texel_buffer(context, pool, VK_FORMAT_R32_UINT, 4, bytes_of(scan_texels),
                                                   "the scanned frames", force_staging);
    if (!buffer) return buffer.error();
    device.scan_frames = std::move(*buffer);
    // The scan's per-row terms in the same order: one fetch in place of the
    // metadata and cost texels, independent of the frame index.
    std::vector<std::array<std::uint32_t, 4>> terms(scan_texels.size());
    for (std::size_t i = 0; i < device.scan_rows; ++i) {
      const std::uint32_t f = scan[i];
      const TagMask tags = database.frame_tags()[f];
      terms[i] = {static_cast<std::uint32_t>(tags), static_cast<std::uint32_t>(tags >> 32),
                  std::bit_cast<std::uint32_t>(database.frame_multiplier()[f]),
                  std::bit_cast<std::uint32_t>(database.frame_bias()[f])};
    }
    Result<TexelBuffer> term_buffer = make_texel_buffer(context, pool, VK_FORMAT_R32G32B32A32_UINT, 16,
                                                        bytes_of(terms), "the scanned frames' terms", force_staging);
    if (!term_buffer) return term_buffer.error();
    device.scan_terms = std::move(*term_buffer);
  }
  return device;
}

}  // namespace mmvk::vulkan::detail
