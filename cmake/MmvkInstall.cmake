# install(EXPORT) + a package config, so `find_package(mmvk)` gives
# mmvk::runtime (and mmvk::vulkan when it was built).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(_mmvk_targets mmvk_runtime)
if(TARGET mmvk_vulkan)
  list(APPEND _mmvk_targets mmvk_vulkan)
endif()
install(TARGETS ${_mmvk_targets} EXPORT mmvkTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY runtime/include/mmvk DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
if(TARGET mmvk_vulkan)
  install(DIRECTORY runtime/vulkan/include/mmvk DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endif()
install(EXPORT mmvkTargets NAMESPACE mmvk:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mmvk)
set(MMVK_HAS_VULKAN OFF)
if(TARGET mmvk_vulkan)
  set(MMVK_HAS_VULKAN ON)
endif()
configure_package_config_file(cmake/mmvkConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/mmvkConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mmvk)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/mmvkConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/mmvkConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/mmvkConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mmvk)
