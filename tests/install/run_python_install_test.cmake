# The install_python test (cmake -P; see CMakeLists.txt beside it for the -D arguments):
#   1. install: DESTDIR=<work>/root cmake --install <build> --component python, which puts the
#               package at <work>/root/<site-packages>/mm (the interpreter's site-packages,
#               MM_PYTHON_INSTALL_DIR, under the scratch root instead of /)
#   2. check:   __init__.py and the extension are there, and nothing else was installed
#   3. import:  from a folder outside the build tree, with only the installed package (and
#               MM_PYTHON_EXTRA_PATH, the numpy folder of Debian's python3) on sys.path: mm.__file__
#               must be the installed one; the installed module builds a database of two clips,
#               loads it back, and prints its feature matrix's shape, which must match.
# Any failure ends in message(FATAL_ERROR) naming the step.
cmake_minimum_required(VERSION 3.25)

foreach(var MM_BUILD_DIR MM_WORK_DIR MM_SITE_DIR MM_PYTHON MM_DATA_DIR)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "install_python: -D${var}=... is required")
  endif()
endforeach()

set(root "${MM_WORK_DIR}/root")
set(site "${root}${MM_SITE_DIR}")
file(REMOVE_RECURSE "${MM_WORK_DIR}")
file(MAKE_DIRECTORY "${MM_WORK_DIR}")

# ---- 1. install
set(ENV{DESTDIR} "${root}")
execute_process(COMMAND "${CMAKE_COMMAND}" --install "${MM_BUILD_DIR}" --component python
                RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
unset(ENV{DESTDIR})
if(NOT result EQUAL 0)
  message(FATAL_ERROR "install_python: step 'install' failed (${result}):\n${out}\n${err}")
endif()

# ---- 2. check what was installed
file(GLOB_RECURSE installed RELATIVE "${root}" "${root}/*")
file(GLOB extension "${site}/mm/_mm*.so")
if(NOT EXISTS "${site}/mm/__init__.py" OR NOT extension)
  message(FATAL_ERROR "install_python: step 'check': expected ${site}/mm/__init__.py and "
                      "_mm*.so, found: ${installed}")
endif()
list(LENGTH installed count)
if(NOT count EQUAL 2)
  message(FATAL_ERROR "install_python: step 'check': expected 2 files, found: ${installed}")
endif()

# ---- 3. import the installed package and use it
file(GLOB clips "${MM_DATA_DIR}/dataset-1_walk_normal_00*.bvh")
list(SORT clips)
list(SUBLIST clips 0 2 clips)
list(LENGTH clips clip_count)
if(NOT clip_count EQUAL 2)
  message(FATAL_ERROR "install_python: step 'import': expected two walk clips in ${MM_DATA_DIR}")
endif()
list(GET clips 0 first)
list(GET clips 1 second)
set(python_path "${site}")
if(MM_PYTHON_EXTRA_PATH)
  string(APPEND python_path ":${MM_PYTHON_EXTRA_PATH}")
endif()
set(ENV{PYTHONPATH} "${python_path}")
execute_process(
  COMMAND "${MM_PYTHON}" -c "
import os, sys
import mm
installed = os.path.realpath(sys.argv[1])
assert os.path.realpath(mm.__file__).startswith(installed + os.sep), (mm.__file__, installed)
built = mm.build_database([sys.argv[2], sys.argv[3]], 'two.mmdb', idle=0)
db = mm.load_database('two.mmdb')
assert db.features.shape == built.features.shape == (db.frame_count, db.feature_dims)
print('features', db.features.shape)
" "${site}" "${first}" "${second}"
  WORKING_DIRECTORY "${MM_WORK_DIR}"
  RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT result EQUAL 0 OR NOT out MATCHES "features \\([0-9]+, 27\\)")
  message(FATAL_ERROR "install_python: step 'import' failed (${result}):\n${out}\n${err}")
endif()
message(STATUS "install_python: ${out}")
