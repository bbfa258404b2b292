// The one way a VkResult is checked: MMVK_VK_CHECK(expr) returns an Error
// naming the call, the result code, the file and the line from the
// enclosing function (which returns Status or Result<T>). Never exits.
#pragma once

#include <string>

#include <vulkan/vulkan.h>

#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"

namespace mmvk::vulkan::detail {

const char* vk_result_name(VkResult result);
Error vk_error(VkResult result, const char* expression, const char* file, int line);

// The calls whose results the Context watches (submits and waits): a
// fault injected for `call` (Context::inject_fault) replaces the real
// result of a wait; a VK_ERROR_DEVICE_LOST marks the Context lost and
// returns Context::device_lost_error().
VkResult injected_or(const Context& context, const char* call, VkResult real);
Status watched(const Context& context, VkResult result, const char* call, const char* expression, const char* file,
               int line);

}  // namespace mmvk::vulkan::detail

#define MMVK_VK_CHECK(expr)                                                                \
  do {                                                                                     \
    const VkResult mmvk_vk_result_ = (expr);                                               \
    if (mmvk_vk_result_ != VK_SUCCESS) {                                                   \
      return ::mmvk::vulkan::detail::vk_error(mmvk_vk_result_, #expr, __FILE__, __LINE__); \
    }                                                                                      \
  } while (false)
