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
  set(subsumed "")
  if("address" IN_LIST TWINCAL_SANITIZERS AND "undefined" IN_LIST TWINCAL_SANITIZERS)
    # UBSan's object-size check tests an access against the size of the whole object the
    # compiler can see (__builtin_object_size, type 0); ASan's shadow memory checks every access
    # against every object at run time, so beside ASan the check finds nothing new. It costs
    # compile time on Eigen's deep inline code: one controllers batch 180 instead of 212 s,
    # core's cholesky.cpp 70 instead of 84 s (2026-11-30, Clang 14, -O1).
    set(subsumed -fno-sanitize=object-size)
  endif()
  target_compile_options(twincal_sanitizers INTERFACE
    -fsanitize=${joined} ${subsumed} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  target_link_options(twincal_sanitizers INTERFACE -fsanitize=${joined})
  set(TWINCAL_SANITIZER_FLAGS "-fsanitize=${joined}")
  message(STATUS "twincal: sanitizers ${joined}")
endif()
