# Finds what the Python bindings need: a Python 3 interpreter that can import numpy, its
# development files, and pybind11. Sets ELLRELOC_PYTHON_FOUND, or ELLRELOC_PYTHON_MISSING to
# what is missing.
#
# Debian's python3-numpy and python3-pytest belong to /usr/bin/python3, while the python3
# first on PATH may be another one (pyenv, a virtual environment) without them: unless
# Python3_EXECUTABLE is given, the first of PATH's python3 and /usr/bin/python3 that imports
# numpy is used.
set(ELLRELOC_PYTHON_FOUND FALSE)
if(NOT Python3_EXECUTABLE)
  find_program(_ellreloc_path_python NAMES python3)
  foreach(candidate ${_ellreloc_path_python} /usr/bin/python3)
    if(EXISTS "${candidate}")
      execute_process(COMMAND ${candidate} -c "import numpy" RESULT_VARIABLE _no_numpy OUTPUT_QUIET ERROR_QUIET)
      if(NOT _no_numpy)
        set(Python3_EXECUTABLE ${candidate} CACHE FILEPATH "Python interpreter for the bindings")
        break()
      endif()
    endif()
  endforeach()
endif()
if(NOT Python3_EXECUTABLE)
  set(ELLRELOC_PYTHON_MISSING "no python3 that can import numpy (python3-numpy)")
  return()
endif()
find_package(Python3 COMPONENTS Interpreter Development.Module QUIET)
if(NOT Python3_Development.Module_FOUND)
  set(ELLRELOC_PYTHON_MISSING "no Python development files for ${Python3_EXECUTABLE} (python3-dev)")
  return()
endif()
set(PYBIND11_FINDPYTHON ON)
find_package(pybind11 2.6 CONFIG QUIET)
if(NOT pybind11_FOUND)
  set(ELLRELOC_PYTHON_MISSING "pybind11 not found (pybind11-dev)")
  return()
endif()
set(ELLRELOC_PYTHON_FOUND TRUE)
message(STATUS "ellreloc: Python bindings for ${Python3_EXECUTABLE} (${Python3_VERSION}), pybind11 ${pybind11_VERSION}")
