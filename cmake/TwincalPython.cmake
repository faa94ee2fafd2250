# The Python bindings (python/): built when pybind11, the Python headers and NumPy are found
# (Debian: pybind11-dev, python3-dev, python3-numpy) and the experiments library is built
# (TWINCAL_BUILD_APPS: the twins and run_experiment come from it), otherwise skipped with a
# message. The
# interpreter is TWINCAL_PYTHON, else Debian's /usr/bin/python3 (a python3 earlier on PATH,
# e.g. pyenv's, may lack NumPy), else whatever FindPython3 finds.
if(NOT TARGET twincal::experiments)
  message(STATUS "twincal: Python bindings skipped (they need TWINCAL_BUILD_APPS=ON)")
  return()
endif()
if(TWINCAL_PYTHON)
  set(Python3_EXECUTABLE "${TWINCAL_PYTHON}")
elseif(NOT DEFINED Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3)
endif()
find_package(Python3 COMPONENTS Interpreter Development.Module NumPy)
if(Python3_FOUND)
  find_package(pybind11 2.10 CONFIG QUIET)
endif()
if(NOT Python3_FOUND OR NOT pybind11_FOUND)
  message(STATUS "twincal: Python bindings skipped (need pybind11-dev, python3-dev, "
                 "python3-numpy)")
  return()
endif()
set(TWINCAL_PYTHON_INSTALL_DIR
  "${CMAKE_INSTALL_LIBDIR}/python${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}/dist-packages"
  CACHE PATH "Where `make install` puts the twincal package (relative: under the prefix)")
add_subdirectory(python)
