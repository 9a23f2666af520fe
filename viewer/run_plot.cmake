# The run plot (`mm-viewer --plot OUT.png`): a software-rendered top-down PNG of a whole run.
# Included from viewer/CMakeLists.txt; paths are relative to this folder.
find_package(PkgConfig REQUIRED)
# GLOBAL: the tests, in another folder, link it too to read the PNGs back.
pkg_check_modules(STB REQUIRED IMPORTED_TARGET GLOBAL stb)  # stb_easy_font, stb_image_write

add_library(mm_viewer_plot STATIC ${CMAKE_CURRENT_LIST_DIR}/src/run_plot.cpp)
target_include_directories(mm_viewer_plot PUBLIC ${CMAKE_CURRENT_LIST_DIR}/src)
target_link_libraries(mm_viewer_plot PUBLIC mm::runtime PRIVATE PkgConfig::STB
                                     $<BUILD_INTERFACE:mm_warnings>)
