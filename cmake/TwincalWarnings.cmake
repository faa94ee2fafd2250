# Strict warnings as errors for twincal's own binaries (tests, benchmarks, examples, apps and
# compiled module sources). Never part of an exported interface: consumers keep their own flags.
add_library(twincal_warnings INTERFACE)
add_library(twincal::warnings ALIAS twincal_warnings)
if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  target_compile_options(twincal_warnings INTERFACE
    -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Wnon-virtual-dtor
    -Wold-style-cast -Wcast-align -Woverloaded-virtual -Wnull-dereference -Wdouble-promotion
    -Werror)
elseif(MSVC)
  target_compile_options(twincal_warnings INTERFACE /W4 /WX /permissive-)
endif()
