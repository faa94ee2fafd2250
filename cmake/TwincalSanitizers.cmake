# TWINCAL_SANITIZERS: a list such as "address;undefined", applied to twincal's own binaries.
add_library(twincal_sanitizers INTERFACE)
# The flags as one string too, for builds outside this project that link our instrumented
# libraries (the package consumer test).
set(TWINCAL_SANITIZER_FLAGS "")
add_library(twincal::sanitizers ALIAS twincal_sanitizers)
if(TWINCAL_SANITIZERS)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    message(FATAL_ERROR "TWINCAL_SANITIZERS needs GCC or Clang, not ${CMAKE_CXX_COMPILER_ID}")
  endif()
  set(known address undefined leak thread memory)
  foreach(sanitizer IN LISTS TWINCAL_SANITIZERS)
    if(NOT sanitizer IN_LIST known)
      message(FATAL_ERROR "TWINCAL_SANITIZERS: unknown sanitizer '${sanitizer}' (known: ${known})")
    endif()
  endforeach()
  list(JOIN TWINCAL_SANITIZERS "," joined)
  target_compile_options(twincal_sanitizers INTERFACE
    -fsanitize=${joined} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  target_link_options(twincal_sanitizers INTERFACE -fsanitize=${joined})
  set(TWINCAL_SANITIZER_FLAGS "-fsanitize=${joined}")
  message(STATUS "twincal: sanitizers ${joined}")
endif()
