# The Python module (python/): built when Python 3 (with its development files) and
# pybind11 are found; otherwise skipped with a note.  The interpreter defaults to the
# system's /usr/bin/python3 — the one Debian's python3-numpy, python3-pytest and
# pybind11-dev belong to — and not the first python3 on PATH (often another one).
# Choose another with -DPython3_EXECUTABLE=/path/to/python3.
# Not in sanitizer builds: an instrumented module cannot be loaded into an interpreter
# that is not.
if(BACKLASH_SANITIZE)
  message(STATUS "backlash: sanitizer build, the Python module is skipped")
  return()
endif()
if(NOT DEFINED Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "Python 3 the module is built for")
endif()
find_package(Python3 COMPONENTS Interpreter Development.Module)
if(Python3_FOUND)
  find_package(pybind11 CONFIG QUIET)
endif()
if(Python3_FOUND AND pybind11_FOUND)
  add_subdirectory(${CMAKE_SOURCE_DIR}/python)
else()
  message(STATUS "backlash: Python 3 development files or pybind11 not found, the Python module is skipped")
endif()
