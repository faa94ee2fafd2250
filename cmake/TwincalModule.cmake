# twincal_add_module(<name> [DEPENDS <target>...] [SOURCES <file>...])
#
# Declares the module target `twincal_<name>` with the alias `twincal::<name>` (exported as
# `twincal::<name>`). Headers live in <name>/include/twincal/<name>/. Without SOURCES the module
# is header-only (an INTERFACE library); with SOURCES it is a compiled library. DEPENDS names the
# targets (other modules or third-party) that the module's public headers need.
function(twincal_add_module name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "DEPENDS;SOURCES")
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
