# mm_library(<name> COMPONENT <game|offline> EXPORT <export set>): the static library mm_<name>
# (mm::<name>, here and installed) of the calling folder's src/*.cpp, its public headers in the
# folder's include/, both installed into the component. The caller adds what it links.
# The Python module (python/) is a shared object that links the static libraries, so when it is
# built their code is compiled position independent; without semantic interposition, so that
# the compiler still inlines and calls directly within a library as in an executable. Only the
# libraries: the programs keep the compiler's default (PIE), which the tests' precompiled header
# must match.
function(mm_shared_object_ready target)
  if(MM_PYTHON_FOUND)
    set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
    target_compile_options(${target} PRIVATE -fno-semantic-interposition)
  endif()
endfunction()

function(mm_library name)
  cmake_parse_arguments(arg "" "COMPONENT;EXPORT" "" ${ARGN})
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/src/*.cpp)
  add_library(mm_${name} STATIC ${sources})
  add_library(mm::${name} ALIAS mm_${name})
  set_target_properties(mm_${name} PROPERTIES EXPORT_NAME ${name})
  target_include_directories(mm_${name} PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
                                               $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(mm_${name} PRIVATE $<BUILD_INTERFACE:mm_warnings>)
  mm_shared_object_ready(mm_${name})
  # The game-facing libraries never read errno after a math function (only after system calls,
  # which -fno-math-errno does not touch). With errno kept, GCC calls the library for every
  # sqrt/sqrtf whose argument it cannot prove non-negative, behind a branch, and does not merge
  # two square roots of one value; without it they are the sqrtss/sqrtsd instruction, which is
  # IEEE-exact, the same bits as the library's.
  if(arg_COMPONENT STREQUAL "game")
    target_compile_options(mm_${name} PRIVATE -fno-math-errno)
  endif()
  install(TARGETS mm_${name} EXPORT ${arg_EXPORT} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          COMPONENT ${arg_COMPONENT})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          COMPONENT ${arg_COMPONENT} FILES_MATCHING PATTERN "*.hpp")
endfunction()
