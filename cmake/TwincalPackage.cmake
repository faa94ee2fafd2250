# Install/export: `find_package(twincal CONFIG REQUIRED)` then link `twincal::twincal` (or a
# single module such as `twincal::core`).
include(CMakePackageConfigHelpers)
set(TWINCAL_CMAKE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/twincal")
install(EXPORT twincalTargets NAMESPACE twincal:: DESTINATION "${TWINCAL_CMAKE_DIR}")
foreach(dependency IN ITEMS SQLITE3 MPI)
  get_property(TWINCAL_PACKAGE_NEEDS_${dependency} GLOBAL PROPERTY
    TWINCAL_PACKAGE_NEEDS_${dependency})
  if(NOT TWINCAL_PACKAGE_NEEDS_${dependency})
    set(TWINCAL_PACKAGE_NEEDS_${dependency} OFF)
  endif()
endforeach()
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
