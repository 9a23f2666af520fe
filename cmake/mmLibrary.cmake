# mm_library(<name> COMPONENT <game|offline> EXPORT <export set>): the static library mm_<name>
# (mm::<name>, here and installed) of the calling folder's src/*.cpp, its public headers in the
# folder's include/, both installed into the component. The caller adds what it links.
function(mm_library name)
  cmake_parse_arguments(arg "" "COMPONENT;EXPORT" "" ${ARGN})
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/src/*.cpp)
  add_library(mm_${name} STATIC ${sources})
  add_library(mm::${name} ALIAS mm_${name})
  set_target_properties(mm_${name} PROPERTIES EXPORT_NAME ${name})
  target_include_directories(mm_${name} PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
                                               $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(mm_${name} PRIVATE $<BUILD_INTERFACE:mm_warnings>)
  install(TARGETS mm_${name} EXPORT ${arg_EXPORT} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          COMPONENT ${arg_COMPONENT})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          COMPONENT ${arg_COMPONENT} FILES_MATCHING PATTERN "*.hpp")
endfunction()
