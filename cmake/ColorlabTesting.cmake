# colorlab_add_gtest(NAME name LABEL unit|integration|conformance|hardware SOURCES ... LIBS ... [TIMEOUT s]
#                   [RESOURCE_LOCK name])  — tests sharing a lock never run at the same time (e.g. the one
#                   GigE Vision fake camera that can serve 127.0.0.1).
# Tests find the built executables through COLORLAB_BIN_DIR and the source tree through
# COLORLAB_SOURCE_DIR; the shared reference data is optional (tests skip with a reason).
function(colorlab_add_gtest)
  cmake_parse_arguments(T "" "NAME;LABEL;TIMEOUT;RESOURCE_LOCK" "SOURCES;LIBS" ${ARGN})
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 300)
  endif()
  add_executable(${T_NAME} ${T_SOURCES})
  set_target_properties(${T_NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  target_link_libraries(${T_NAME} PRIVATE ${T_LIBS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${T_NAME} PRIVATE
    COLORLAB_BIN_DIR="${CMAKE_BINARY_DIR}/bin"
    COLORLAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  colorlab_warnings(${T_NAME})
  set(_props LABELS ${T_LABEL} TIMEOUT ${T_TIMEOUT})
  if(T_RESOURCE_LOCK)
    list(APPEND _props RESOURCE_LOCK ${T_RESOURCE_LOCK})
  endif()
  gtest_discover_tests(${T_NAME} PROPERTIES ${_props} DISCOVERY_TIMEOUT 60)
endfunction()
