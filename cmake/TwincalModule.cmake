# twincal_add_module(<name> [UNITY] [DEPENDS <target>...] [SOURCES <file>...])
#
# Declares the module target `twincal_<name>` with the alias `twincal::<name>` (exported as
# `twincal::<name>`). Headers live in <name>/include/twincal/<name>/. Without SOURCES the module
# is header-only (an INTERFACE library); with SOURCES it is a compiled library. DEPENDS names the
# targets (other modules or third-party) that the module's public headers need.
# UNITY compiles the sources in batches of 8, so that the headers they share (Eigen, fmt,
# nlohmann-json, the module's own) are parsed and their templates instantiated once per batch:
# their file-scope names must then be distinct across the module. A source whose own
# instantiations dominate (a file per sigma-point scheme) opts out with the source property
# SKIP_UNITY_BUILD_INCLUSION, to keep compiling in parallel. Measured (Clang 14, release, one
# file after another, 2026-11-26): the experiments, sheet_metal, calculix, serve and distributed
# sources took 235 instead of 433 CPU-s; the build compiles them in each of CI's three stages.
function(twincal_add_module name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "UNITY" "" "DEPENDS;SOURCES")
  if(arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "twincal_add_module(${name}): unknown arguments '${arg_UNPARSED_ARGUMENTS}'")
  endif()
  set(target twincal_${name})
  set(include_dir "${CMAKE_CURRENT_SOURCE_DIR}/include")
  if(NOT EXISTS "${include_dir}/twincal/${name}")
    message(FATAL_ERROR "twincal_add_module(${name}): missing ${include_dir}/twincal/${name}")
  endif()

  if(arg_SOURCES)
    add_library(${target} ${arg_SOURCES})
    set(scope PUBLIC)
    if(arg_UNITY)
      set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
    endif()
    # Build-only: a static library exports its private link dependencies, and these two are not
    # part of the installed package.
    target_link_libraries(${target} PRIVATE
      $<BUILD_INTERFACE:twincal::warnings> $<BUILD_INTERFACE:twincal::sanitizers>)
  else()
    add_library(${target} INTERFACE)
    set(scope INTERFACE)
  endif()
  add_library(twincal::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  target_compile_features(${target} ${scope} cxx_std_20)
  target_include_directories(${target} ${scope}
    $<BUILD_INTERFACE:${include_dir}>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${target} ${scope} ${arg_DEPENDS})

  install(DIRECTORY "${include_dir}/twincal" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")
  install(TARGETS ${target} EXPORT twincalTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
endfunction()
