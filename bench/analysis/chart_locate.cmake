# Chart locating and sampling at 3504×2336 (issue 14); numbers and command in docs/PERFORMANCE.md.
if(TARGET colorlab_chart_locate)
  add_executable(bench_analysis_chart_locate ${CMAKE_CURRENT_LIST_DIR}/bench_chart_locate.cpp)
  target_link_libraries(bench_analysis_chart_locate PRIVATE colorlab_chart_locate colorlab_sim_camera colorlab_sim_scene benchmark::benchmark)
  colorlab_warnings(bench_analysis_chart_locate)
endif()
