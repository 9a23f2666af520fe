# The install_example test (cmake -P; see CMakeLists.txt beside it for the -D arguments):
#   1. install:   cmake --install <build> --prefix <work>/prefix (a fresh prefix every run)
#   2. configure: examples/crowd into <work>/example-build with CMAKE_PREFIX_PATH=<prefix> only,
#                 the build's generator and compiler, Release, warnings as errors; mm must be
#                 found in the prefix (not the build tree, not a package registry)
#   3. build:     the example
#   4. database:  the installed `mm build` over six real BVH clips
#   5. run:       the example with that database, 100 characters, 2 s
#   6. check:     exactly one "character N:" line for each N in 0..99, every number finite, and
#                 more than half of the characters moved more than 0.1 m from their start.
#   7. capsules:  examples/capsules (configured and built in step 3, against the game component
#                 alone) run with the same database, 8 characters, 8 s: each capsule Bullet moved
#                 ends on the level's surface (within 2 cm of the ground under it), climbed the
#                 0.9 m stairs and stopped at the wall (z <= 7.7 + 5 mm).
# Any failure ends in message(FATAL_ERROR) naming the step.
cmake_minimum_required(VERSION 3.25)  # this script's policies (IN_LIST), as the project's

foreach(var MM_BUILD_DIR MM_EXAMPLE_SOURCE_DIR MM_CAPSULES_SOURCE_DIR MM_WORK_DIR MM_DATA_DIR
            MM_GENERATOR MM_CXX_COMPILER)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "install_example: -D${var}=... is required")
  endif()
endforeach()

set(prefix "${MM_WORK_DIR}/prefix")
set(example_build "${MM_WORK_DIR}/example-build")
set(capsules_build "${MM_WORK_DIR}/capsules-build")
set(database "${MM_WORK_DIR}/crowd.mmdb")
set(characters 100)
set(seconds 2)

# Runs one step; on failure stops the test with the step's name, the command and its output.
# The output is left in `step_output`.
function(run_step step)
  message(STATUS "install_example: ${step}")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT result EQUAL 0)
    list(JOIN ARGN " " command)
    message(FATAL_ERROR "install_example: step '${step}' failed (${result}).\n"
                        "command: ${command}\nstdout:\n${out}\nstderr:\n${err}")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

# ---- 1. install into a fresh prefix, so nothing left from an earlier run can make it pass.
file(REMOVE_RECURSE "${prefix}" "${example_build}" "${capsules_build}" "${database}")
# What a game links alone: the example must configure and build against the game component with
# nothing of the offline side (or the programs) present.
run_step(install "${CMAKE_COMMAND}" --install "${MM_BUILD_DIR}" --prefix "${prefix}"
         --component game)
foreach(expected include/mm/controller/controller.hpp include/mm/database/database_file.hpp
                 include/mm/search/search.hpp include/mm/runtime/spring.hpp
                 lib/cmake/mm/mmConfig.cmake lib/cmake/mm/mmTargets.cmake)
  if(NOT EXISTS "${prefix}/${expected}")
    message(FATAL_ERROR "install_example: step 'install' did not install ${expected}")
  endif()
endforeach()
file(GLOB_RECURSE game_files RELATIVE "${prefix}" "${prefix}/*")
foreach(file IN LISTS game_files)
  if(file MATCHES "offline|Offline|workers|evaluation|crowd\\.hpp|^bin/")
    message(FATAL_ERROR "install_example: the game component installed ${file}")
  endif()
endforeach()

set(configure_args
    -G "${MM_GENERATOR}"
    "-DCMAKE_CXX_COMPILER=${MM_CXX_COMPILER}"
    -DCMAKE_BUILD_TYPE=Release
    "-DCMAKE_PREFIX_PATH=${prefix}"
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
    -DCMAKE_COMPILE_WARNING_AS_ERROR=ON
    "-DCMAKE_CXX_FLAGS=${MM_CXX_FLAGS}"
    "-DCMAKE_EXE_LINKER_FLAGS=${MM_LINKER_FLAGS}")
if(MM_MAKE_PROGRAM)
  list(APPEND configure_args "-DCMAKE_MAKE_PROGRAM=${MM_MAKE_PROGRAM}")
endif()
run_step(configure "${CMAKE_COMMAND}" -S "${MM_EXAMPLE_SOURCE_DIR}" -B "${example_build}"
         ${configure_args})
file(STRINGS "${example_build}/CMakeCache.txt" mm_dir_line REGEX "^mm_DIR:")
string(REGEX REPLACE "^mm_DIR:[A-Z]+=" "" mm_dir "${mm_dir_line}")
file(REAL_PATH "${prefix}" real_prefix)
if(EXISTS "${mm_dir}")
  file(REAL_PATH "${mm_dir}" mm_dir)
endif()
string(FIND "${mm_dir}/" "${real_prefix}/" at)
if(NOT at EQUAL 0)
  message(FATAL_ERROR "install_example: step 'configure' found mm at '${mm_dir}', "
                      "not in the installed prefix ${prefix}")
endif()

# ---- 3. build it.
run_step(build "${CMAKE_COMMAND}" --build "${example_build}")
set(example "${example_build}/mm-crowd-example")
if(NOT EXISTS "${example}")
  message(FATAL_ERROR "install_example: step 'build' made no ${example}")
endif()
# The second example, against the game component alone too: Bullet is its own dependency.
run_step(configure-capsules "${CMAKE_COMMAND}" -S "${MM_CAPSULES_SOURCE_DIR}" -B "${capsules_build}"
         ${configure_args})
run_step(build-capsules "${CMAKE_COMMAND}" --build "${capsules_build}")
set(capsules "${capsules_build}/mm-capsules-example")

# The rest (the offline component and the programs): `mm build` makes the example's database,
# and the offline component is found when asked for.
run_step(install-rest "${CMAKE_COMMAND}" --install "${MM_BUILD_DIR}" --prefix "${prefix}")
foreach(expected bin/mm include/mm/offline/builder.hpp lib/cmake/mm/mmOfflineTargets.cmake)
  if(NOT EXISTS "${prefix}/${expected}")
    message(FATAL_ERROR "install_example: step 'install-rest' did not install ${expected}")
  endif()
endforeach()

# ---- 4. a small database from real data, made by the installed command line.
set(clips dataset-2_walk_normal_001 dataset-2_walk_normal_002 dataset-2_walk_normal_003
          dataset-2_walk-turn-left_normal_001 dataset-2_run_normal_001
          dataset-2_wave-left-hand_normal_001)
set(clip_files "")
foreach(clip ${clips})
  if(NOT EXISTS "${MM_DATA_DIR}/${clip}.bvh")
    message(STATUS "install_example: SKIPPED the run: no ${MM_DATA_DIR}/${clip}.bvh "
                   "(the install and the example's build passed)")
    return()
  endif()
  list(APPEND clip_files "${MM_DATA_DIR}/${clip}.bvh")
endforeach()
run_step(database "${prefix}/bin/mm" build ${clip_files} -o "${database}" --quiet)

# ---- 5. run it.
run_step(run "${example}" "${database}" ${characters} ${seconds})
set(output "${step_output}")
message(STATUS "install_example: the example printed:\n${output}")

# ---- 6. check what it printed.
string(REGEX MATCHALL "character [0-9]+:[^\n]*" lines "${output}")
list(LENGTH lines line_count)
if(NOT line_count EQUAL characters)
  message(FATAL_ERROR "install_example: step 'check': ${line_count} \"character N:\" lines, "
                      "expected ${characters}")
endif()
# Numbers as printf's %.3f / %.1f print finite values; nan and inf do not match.
set(num "(-?[0-9]+\\.[0-9][0-9][0-9])")
string(CONCAT line_regex "^character ([0-9]+): x=${num} z=${num} yaw_deg=(-?[0-9]+\\.[0-9]) "
                         "\\(started at x=${num} z=${num}\\)$")
set(seen "")
set(moved 0)
foreach(line IN LISTS lines)
  if(NOT line MATCHES "${line_regex}")
    message(FATAL_ERROR "install_example: step 'check': unexpected or non-finite line: ${line}")
  endif()
  set(index ${CMAKE_MATCH_1})
  if(index IN_LIST seen OR index GREATER_EQUAL characters)
    message(FATAL_ERROR "install_example: step 'check': character ${index} repeated or "
                        "out of range")
  endif()
  list(APPEND seen ${index})
  # Millimetres as integers: every position has exactly three decimals.
  foreach(n 2 3 5 6)
    string(REPLACE "." "" mm_${n} "${CMAKE_MATCH_${n}}")
  endforeach()
  math(EXPR dx "${mm_2} - (${mm_5})")
  math(EXPR dz "${mm_3} - (${mm_6})")
  math(EXPR squared "${dx} * ${dx} + ${dz} * ${dz}")
  if(squared GREATER 10000)  # more than 100 mm
    math(EXPR moved "${moved} + 1")
  endif()
endforeach()
# Each character's varied input walks or runs most of the time: a working controller moves
# nearly all of them in 2 s; one that never leaves its spot (or a broken teleport) moves none.
math(EXPR half "${characters} / 2")
if(NOT moved GREATER half)
  message(FATAL_ERROR "install_example: step 'check': only ${moved} of ${characters} characters "
                      "moved more than 0.1 m from their start")
endif()
if(NOT output MATCHES "\nsummary: [^\n]*\n?$")
  message(FATAL_ERROR "install_example: step 'check': no summary line at the end")
endif()

# ---- 7. the capsules example: each capsule on the surface, up the stairs, stopped at the wall.
set(capsule_count 8)
run_step(run-capsules "${capsules}" "${database}" ${capsule_count} 8)
set(output "${step_output}")
message(STATUS "install_example: the capsules example printed:\n${output}")
string(REGEX MATCHALL "character [0-9]+:[^\n]*" lines "${output}")
list(LENGTH lines line_count)
if(NOT line_count EQUAL capsule_count)
  message(FATAL_ERROR "install_example: step 'capsules': ${line_count} \"character N:\" lines, "
                      "expected ${capsule_count}")
endif()
string(CONCAT line_regex "^character [0-9]+: x=${num} y=${num} z=${num} ground=${num} "
                         "highest=${num}$")
foreach(line IN LISTS lines)
  if(NOT line MATCHES "${line_regex}")
    message(FATAL_ERROR "install_example: step 'capsules': unexpected or non-finite line: ${line}")
  endif()
  foreach(n 2 3 4 5)  # millimetres as integers
    string(REPLACE "." "" mm_${n} "${CMAKE_MATCH_${n}}")
  endforeach()
  math(EXPR above "${mm_2} - (${mm_4})")
  if(above LESS -10 OR above GREATER 20 OR mm_5 LESS 850 OR mm_3 GREATER 7705)
    message(FATAL_ERROR "install_example: step 'capsules': not on the landing at the wall "
                        "(within 2 cm of the ground, up the 0.9 m stairs, z <= 7.705): ${line}")
  endif()
endforeach()

message(STATUS "install_example: passed (${moved} of ${characters} characters moved; "
               "${capsule_count} capsules up the stairs and at the wall)")
