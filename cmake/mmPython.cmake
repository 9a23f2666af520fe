# The Python module's prerequisites (python/): a Python 3 interpreter with its development
# files, pybind11 (Debian: python3-dev, pybind11-dev), and numpy (python3-numpy) for that
# interpreter. Sets MM_PYTHON_FOUND, and MM_PYTHON_EXTRA_PATH: a folder the module appends to
# sys.path when the interpreter cannot import numpy itself.
#
# The interpreter is FindPython3's (the first python3 on PATH; -DPython3_EXECUTABLE=... picks
# another), because `python3` is the interpreter a user imports the module from and installs it
# into. Debian installs numpy, pytest and matplotlib for /usr/bin/python3 only; where PATH leads
# to another build of the same Python version (pyenv, a self-built Python), that interpreter
# can load those packages but does not look for them. MM_PYTHON_EXTRA_PATH is then the folder
# Debian's python3 imports numpy from, and the module and the tests add it.
set(MM_PYTHON_FOUND OFF)
set(MM_PYTHON_EXTRA_PATH "")
find_package(Python3 3.8 COMPONENTS Interpreter Development.Module QUIET)
if(NOT Python3_FOUND)
  message(STATUS "Python module: skipped (no Python 3 interpreter with development files; "
                 "Debian: python3-dev)")
  return()
endif()
find_package(pybind11 2.6 CONFIG QUIET)
if(NOT pybind11_FOUND)
  message(STATUS "Python module: skipped (no pybind11; Debian: pybind11-dev)")
  return()
endif()

# The folder an interpreter imports numpy from, or "" when it cannot.
function(mm_numpy_folder interpreter out)
  execute_process(
    COMMAND ${interpreter} -c
            "import os, numpy; print(os.path.dirname(os.path.dirname(numpy.__file__)))"
    OUTPUT_VARIABLE folder OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE failed)
  if(failed)
    set(folder "")
  endif()
  set(${out} "${folder}" PARENT_SCOPE)
endfunction()

mm_numpy_folder(${Python3_EXECUTABLE} numpy_folder)
if(NOT numpy_folder AND EXISTS /usr/bin/python3)
  execute_process(COMMAND /usr/bin/python3 -c
                          "import sys; print('%d.%d' % sys.version_info[:2])"
                  OUTPUT_VARIABLE system_version OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(system_version STREQUAL "${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}")
    mm_numpy_folder(/usr/bin/python3 numpy_folder)
    set(MM_PYTHON_EXTRA_PATH "${numpy_folder}")
  endif()
endif()
if(NOT numpy_folder)
  message(STATUS "Python module: skipped (${Python3_EXECUTABLE} cannot import numpy, nor can a "
                 "/usr/bin/python3 of the same version; Debian: python3-numpy)")
  return()
endif()
set(MM_PYTHON_FOUND ON)
message(STATUS "Python module: for ${Python3_EXECUTABLE} (${Python3_VERSION}), numpy from "
               "${numpy_folder}")
