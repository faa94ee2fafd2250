# The Python the tests run: while ctest runs a test, the directory of TWINCAL_PYTHON (else
# Debian's /usr/bin/python3, the interpreter the bindings are built for, with Debian's NumPy)
# comes first on PATH, so that `python3` in an external twin's command, and a twin script's
# `#!/usr/bin/env python3`, start that interpreter and not whatever the user's PATH has first.
# A version manager's shim is slow to start: pyenv's took 0.38 s per start against 0.04 s for
# /usr/bin/python3, and the suites start Python hundreds of times (one test of the experiments
# suite 73 times).
#
# twincal_test_environment(): gives that PATH to every test the calling directory has declared
# (add_test) so far. TWINCAL_TEST_PROPERTIES: the same as test properties, for
# gtest_discover_tests(… PROPERTIES …); empty where no interpreter is found.
set(TWINCAL_PYTHON "" CACHE FILEPATH
  "Python interpreter of the bindings and the tests (default /usr/bin/python3)")
if(TWINCAL_PYTHON)
  set(twincal_test_python "${TWINCAL_PYTHON}")
elseif(EXISTS /usr/bin/python3)
  set(twincal_test_python /usr/bin/python3)
else()
  find_program(twincal_test_python python3)
endif()
set(TWINCAL_TEST_PROPERTIES "")
if(twincal_test_python)
  get_filename_component(twincal_test_python_directory "${twincal_test_python}" DIRECTORY)
  set(TWINCAL_TEST_PROPERTIES
    ENVIRONMENT_MODIFICATION "PATH=path_list_prepend:${twincal_test_python_directory}")
endif()

function(twincal_test_environment)
  get_property(tests DIRECTORY PROPERTY TESTS)
  if(tests AND TWINCAL_TEST_PROPERTIES)
    set_tests_properties(${tests} PROPERTIES ${TWINCAL_TEST_PROPERTIES})
  endif()
endfunction()
