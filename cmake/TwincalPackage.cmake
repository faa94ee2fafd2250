# Install/export: `find_package(twincal CONFIG REQUIRED)` then link `twincal::twincal` (or a
# single module such as `twincal::core`).
include(CMakePackageConfigHelpers)
set(TWINCAL_CMAKE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/twincal")
install(EXPORT twincalTargets NAMESPACE twincal:: DESTINATION "${TWINCAL_CMAKE_DIR}")
get_property(TWINCAL_PACKAGE_NEEDS_SQLITE3 GLOBAL PROPERTY TWINCAL_PACKAGE_NEEDS_SQLITE3)
if(NOT TWINCAL_PACKAGE_NEEDS_SQLITE3)
  set(TWINCAL_PACKAGE_NEEDS_SQLITE3 OFF)
endif()
configure_package_config_file(
  "${PROJECT_SOURCE_DIR}/cmake/twincalConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/twincalConfig.cmake"
  INSTALL_DESTINATION "${TWINCAL_CMAKE_DIR}")
write_basic_package_version_file(
  "${PROJECT_BINARY_DIR}/twincalConfigVersion.cmake"
  COMPATIBILITY SameMinorVersion)
install(FILES
  "${PROJECT_BINARY_DIR}/twincalConfig.cmake"
  "${PROJECT_BINARY_DIR}/twincalConfigVersion.cmake"
  DESTINATION "${TWINCAL_CMAKE_DIR}")
