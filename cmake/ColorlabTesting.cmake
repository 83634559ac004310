# colorlab_add_gtest(NAME name LABEL unit|integration|conformance|hardware SOURCES ... LIBS ... [TIMEOUT s]
#                   [RESOURCE_LOCK name] [TUNING pattern...])  — tests sharing a lock never run at the same time
#                   (e.g. the one GigE Vision fake camera that can serve 127.0.0.1). TUNING names, as gtest filter
#                   patterns, the tests that check the simulator's tuning to the dissertation rather than the code:
#                   they get the label `tuning` beside LABEL (docs/TESTING.md, "Analytic truth and tuning checks").
# Tests find the built executables through COLORLAB_BIN_DIR and the source tree through
# COLORLAB_SOURCE_DIR; the shared reference data is optional (tests skip with a reason).
function(colorlab_add_gtest)
  cmake_parse_arguments(T "" "NAME;LABEL;TIMEOUT;RESOURCE_LOCK" "SOURCES;LIBS;TUNING" ${ARGN})
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 300)
  endif()
  # A source that colorlab_test_support_library compiled once for this directory is linked, not compiled again.
  get_property(_shared DIRECTORY PROPERTY COLORLAB_TEST_SUPPORT_SOURCES)
  set(_sources)
  set(_support)
  foreach(_src IN LISTS T_SOURCES)
    get_filename_component(_abs ${_src} ABSOLUTE)
    set(_lib)
    foreach(_entry IN LISTS _shared)
      string(FIND "${_entry}" "${_abs}=" _at)
      if(_at EQUAL 0)
        string(LENGTH "${_abs}=" _len)
        string(SUBSTRING "${_entry}" ${_len} -1 _lib)
      endif()
    endforeach()
    if(_lib)
      list(APPEND _support ${_lib})
    else()
      list(APPEND _sources ${_src})
    endif()
  endforeach()
  add_executable(${T_NAME} ${_sources})
  set_target_properties(${T_NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  target_link_libraries(${T_NAME} PRIVATE ${_support} ${T_LIBS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${T_NAME} PRIVATE
    COLORLAB_BIN_DIR="${CMAKE_BINARY_DIR}/bin"
    COLORLAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  colorlab_warnings(${T_NAME})
  set(_props LABELS ${T_LABEL} TIMEOUT ${T_TIMEOUT})
  if(T_RESOURCE_LOCK)
    list(APPEND _props RESOURCE_LOCK ${T_RESOURCE_LOCK})
  endif()
  if(T_TUNING)
    # Two discoveries of the same binary, split by gtest filter: every test is registered exactly once, under its
    # usual name. gtest_discover_tests cannot pass a list-valued property (LABELS "unit;tuning" arrives split), so
    # the second label is set by a script ctest runs after the discovered tests are loaded, from their TEST_LIST.
    list(JOIN T_TUNING ":" _tuning)
    gtest_discover_tests(${T_NAME} TEST_FILTER "-${_tuning}" TEST_LIST ${T_NAME}_TESTS
                         PROPERTIES ${_props} DISCOVERY_TIMEOUT 60)
    gtest_discover_tests(${T_NAME} TEST_FILTER "${_tuning}" TEST_LIST ${T_NAME}_TUNING_TESTS
                         PROPERTIES ${_props} DISCOVERY_TIMEOUT 60)
    set(_labels_file "${CMAKE_CURRENT_BINARY_DIR}/${T_NAME}_tuning_labels.cmake")
    file(WRITE "${_labels_file}"
         "foreach(_test IN LISTS ${T_NAME}_TUNING_TESTS)\n"
         "  set_tests_properties(\"\${_test}\" PROPERTIES LABELS \"${T_LABEL};tuning\")\n"
         "endforeach()\n")
    set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${_labels_file}")
  else()
    gtest_discover_tests(${T_NAME} PROPERTIES ${_props} DISCOVERY_TIMEOUT 60)
  endif()
endfunction()

# colorlab_test_support_library(NAME name SOURCES ... LIBS ...)  — support sources that many test executables of
# one directory list in their SOURCES (e.g. tests/integration/resume_support.cpp), compiled once into a static
# library with the defines colorlab_add_gtest gives a test; a later colorlab_add_gtest in the same directory that
# lists one of them links this library in its place. Saves one compile of the file per test that shares it.
function(colorlab_test_support_library)
  cmake_parse_arguments(L "" "NAME" "SOURCES;LIBS" ${ARGN})
  add_library(${L_NAME} STATIC ${L_SOURCES})
  target_link_libraries(${L_NAME} PUBLIC ${L_LIBS} GTest::gtest)
  target_compile_definitions(${L_NAME} PRIVATE
    COLORLAB_BIN_DIR="${CMAKE_BINARY_DIR}/bin"
    COLORLAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  colorlab_warnings(${L_NAME})
  foreach(_src IN LISTS L_SOURCES)
    get_filename_component(_abs ${_src} ABSOLUTE)
    set_property(DIRECTORY APPEND PROPERTY COLORLAB_TEST_SUPPORT_SOURCES "${_abs}=${L_NAME}")
  endforeach()
endfunction()
