# Links `target` to mmvk::vulkan where the Vulkan backend is built (the link
# is `scope`: PUBLIC for a library whose users reach Vulkan through it) and
# defines MMVK_HAS_VULKAN=1 for the target's own sources. The macro is
# PRIVATE, so a header that other targets include must not depend on it.
function(mmvk_use_vulkan target scope)
  if(TARGET mmvk::vulkan)
    target_link_libraries(${target} ${scope} mmvk::vulkan)
    target_compile_definitions(${target} PRIVATE MMVK_HAS_VULKAN=1)
  endif()
endfunction()
