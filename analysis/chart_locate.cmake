# Finding a ColorChecker in a photograph (chart_locate.hpp): OpenCV stays private to this target.
find_package(OpenCV 4 QUIET COMPONENTS core imgproc calib3d imgcodecs)
if(OpenCV_FOUND)
  add_library(colorlab_chart_locate
    ${CMAKE_CURRENT_LIST_DIR}/src/chart_layout.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/chart_photo.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/chart_locate/working_image.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/chart_locate/patch_quads.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/chart_locate/lens.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/chart_locate/homography.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/chart_locate/lattice.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/chart_locate/orientation.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/chart_locate/centroid_refit.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/chart_locate/self_check.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/chart_locate/patch_sampler.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/chart_locate/locate.cpp)
  add_library(colorlab::chart_locate ALIAS colorlab_chart_locate)
  target_include_directories(colorlab_chart_locate PUBLIC ${CMAKE_CURRENT_LIST_DIR}/include)
  target_link_libraries(colorlab_chart_locate
    PUBLIC colorlab::analysis colorlab::core
    PRIVATE opencv_core opencv_imgproc opencv_calib3d opencv_imgcodecs)
  target_include_directories(colorlab_chart_locate SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
  colorlab_warnings(colorlab_chart_locate)
else()
  message(FATAL_ERROR "colorlab needs OpenCV (core, imgproc, calib3d, imgcodecs): apt-get install libopencv-dev")
endif()
