// The header every VkPipelineCache blob starts with
// (VkPipelineCacheHeaderVersionOne), checked before a blob reaches the
// driver: a blob from another device or driver version, a truncated file or
// garbage is then ignored with a reason instead of trusted to the driver.
#pragma once

#include <cstddef>
#include <span>

#include <vulkan/vulkan.h>

#include "mmvk/common/status.hpp"

namespace mmvk::vulkan::detail {

// OK when `blob` has a version-one header that names this device (vendor,
// device id, pipelineCacheUUID: the driver build); the error says which
// field differs.
Status check_pipeline_cache_blob(std::span<const std::byte> blob, const VkPhysicalDeviceProperties& device);

}  // namespace mmvk::vulkan::detail
