# What each fuzz target's parser is made of, as source groups: a group's own source files (compiled on
# their own, so the libFuzzer build need not build the device- and database-laden library around a
# parser) and the small libraries it links. Shared by the libFuzzer build (fuzz_targets.cmake) and the
# normal build's regression test (CMakeLists.txt), so both run exactly the same parser code.
#
# A group's sources compile once per build, whatever the number of targets using them: in the libFuzzer
# build each group is one object library with the fuzz flags (COLORLAB_FUZZ_GROUP_OPTIONS), linked by
# every target that needs it; in the normal build a group that is exactly the sources of a library the
# project already builds links that library instead of compiling its files a second time.
set(COLORLAB_FUZZ_TARGETS
  spectrolino_wire dmx_wire ls110_reply cgats csv pgm http_target http_request config_toml
  campaign_script campaign_params hid_socket simdslr_socket)

# colorlab_fuzz_target_groups(<fuzz target name> <out var>): the groups a target's parser needs.
function(colorlab_fuzz_target_groups name out)
  if(name STREQUAL "spectrolino_wire" OR name STREQUAL "dmx_wire" OR name STREQUAL "ls110_reply")
    set(groups wire)
  elseif(name STREQUAL "cgats" OR name STREQUAL "csv")
    set(groups analysis_text)
  elseif(name STREQUAL "pgm")
    set(groups pgm)
  elseif(name STREQUAL "http_target" OR name STREQUAL "http_request")
    set(groups http_message)
  elseif(name STREQUAL "config_toml")
    set(groups daemon_config)
  elseif(name STREQUAL "campaign_script" OR name STREQUAL "campaign_params")
    set(groups campaign_engine)
  elseif(name STREQUAL "hid_socket")
    set(groups hid_socket line_client)
  elseif(name STREQUAL "simdslr_socket")
    set(groups simdslr line_client)
  else()
    message(FATAL_ERROR "colorlab_fuzz_parser: no parser named ${name}")
  endif()
  set(${out} ${groups} PARENT_SCOPE)
endfunction()

# colorlab_fuzz_group(<group>): sets _sources, _includes, _libs and _library (the normal build's library
# holding exactly _sources, or empty) in the caller's scope.
function(colorlab_fuzz_group group)
  set(s ${PROJECT_SOURCE_DIR})
  set(sources)
  set(includes)
  set(libs colorlab::core)
  set(library)
  if(group STREQUAL "wire")
    list(APPEND libs colorlab::wire_protocols)
  elseif(group STREQUAL "analysis_text")
    list(APPEND sources ${s}/analysis/src/cgats.cpp ${s}/analysis/src/csv.cpp ${s}/analysis/src/csv_write.cpp)
    list(APPEND includes ${s}/analysis/include)
    set(library colorlab::analysis)
  elseif(group STREQUAL "pgm")
    list(APPEND sources ${s}/client/analyze/src/pgm_reader.cpp)
    list(APPEND includes ${s}/client/analyze/src)
  elseif(group STREQUAL "http_message")
    # Compiled in the normal build too (not linked from colorlab::http): the regression test turns Boost's
    # assertions off (BOOST_DISABLE_ASSERTS) for the asan preset's Debug build, see CMakeLists.txt.
    list(APPEND sources ${s}/daemon/http/src/message.cpp)
    list(APPEND includes ${s}/daemon/http/include)
    list(APPEND libs colorlab::protocol colorlab_asio)
  elseif(group STREQUAL "daemon_config")
    list(APPEND sources ${s}/daemon/core/src/config.cpp)
    list(APPEND includes ${s}/daemon/core/include ${s}/drivers/factory/include ${s}/drivers/core/include)
    # toml++ is Debian's shared build, as colorlabd links it: its parser is not instrumented, so the
    # fuzzer is guided by config.cpp's branches alone (the seeds and dictionary give it valid TOML). Two
    # toml++ 3.3.0 bugs seen when it was compiled in under the sanitizers are upstream's: an assertion on a
    # table header such as `[)x]` (marzer/tomlplusplus PR #301; the shipped build answers a parse_error)
    # and an "unreachable" in its Unicode whitespace table (issues #190, #295; PR #305).
    list(APPEND libs colorlab::protocol colorlab_asio nlohmann_json::nlohmann_json PkgConfig::TOMLPP)
    # [cabinet]: verify/scene's parser and validation, linked as built (not fuzzed here; its own tests cover it).
    list(APPEND libs colorlab::verify_scene)
  elseif(group STREQUAL "campaign_engine")
    # The declaration sandbox and the `lab` table a script's top level sees, with the catalogue's
    # sequences: the engine's sources, fuzzed. The table is built from the lab's registry of calls
    # (lab_calls.hpp), whose rows name the live lab's and the dry run's handlers, and lab_api's analysis
    # functions (characterize, chart_plan, floor_luminance_fit) are procedures: both come linked, as
    # colorlab_campaign_lab (procedures with it), built plain in the libFuzzer build (fuzz_targets.cmake).
    foreach(f lua_sandbox lua_value lab_api script catalogue sequence)
      list(APPEND sources ${s}/campaigns/engine/src/${f}.cpp)
    endforeach()
    list(APPEND includes ${s}/campaigns/engine/include)
    list(APPEND libs colorlab::campaign_lab colorlab::campaign_procedures colorlab::analysis PkgConfig::LUA
         OpenSSL::Crypto nlohmann_json::nlohmann_json)
    set(library colorlab::campaigns)
  elseif(group STREQUAL "hid_socket")
    list(APPEND sources ${s}/drivers/lamps/src/socket_hid_transport.cpp)
    list(APPEND includes ${s}/drivers/lamps/include ${s}/drivers/core/include)
    list(APPEND libs colorlab::wire_protocols nlohmann_json::nlohmann_json Threads::Threads)
    set(library colorlab::drivers_lamps)
  elseif(group STREQUAL "line_client")
    list(APPEND sources ${s}/drivers/core/src/unix_line_client.cpp)
    list(APPEND includes ${s}/drivers/core/include)
    list(APPEND libs nlohmann_json::nlohmann_json Threads::Threads)
    set(library colorlab::drivers_core)
  elseif(group STREQUAL "simdslr")
    # The driver with the Camera base class it derives from (worker thread, the capture pipeline's
    # LibRaw decoder, the gphoto2 driver's shutter labels and raw file names).
    foreach(f sim_dslr_camera camera camera_settings worker_thread raw_image raw_decoder gphoto2_camera)
      list(APPEND sources ${s}/drivers/camera/src/${f}.cpp)
    endforeach()
    list(APPEND includes ${s}/drivers/camera/include ${s}/drivers/core/include)
    list(APPEND libs nlohmann_json::nlohmann_json Threads::Threads PkgConfig::LIBRAW PkgConfig::GPHOTO2)
    set(library colorlab::drivers_camera)
  else()
    message(FATAL_ERROR "colorlab_fuzz_group: no source group named ${group}")
  endif()
  set(_sources ${sources} PARENT_SCOPE)
  set(_includes ${includes} PARENT_SCOPE)
  set(_libs ${libs} PARENT_SCOPE)
  set(_library ${library} PARENT_SCOPE)
endfunction()

# colorlab_fuzz_parser(<cmake target> <fuzz target name>)
function(colorlab_fuzz_parser target name)
  colorlab_fuzz_target_groups(${name} groups)
  foreach(group IN LISTS groups)
    colorlab_fuzz_group(${group})
    if(NOT _sources)
      target_link_libraries(${target} PRIVATE ${_libs})
    elseif(COLORLAB_FUZZ)
      set(lib colorlab_fuzz_group_${group})
      if(NOT TARGET ${lib})
        add_library(${lib} OBJECT ${_sources})
        target_include_directories(${lib} PUBLIC ${_includes})
        target_link_libraries(${lib} PUBLIC ${_libs})
        target_compile_options(${lib} PRIVATE ${COLORLAB_FUZZ_GROUP_OPTIONS})
        colorlab_warnings(${lib})
      endif()
      target_link_libraries(${target} PRIVATE ${lib})
    elseif(_library)
      target_include_directories(${target} PRIVATE ${_includes})
      target_link_libraries(${target} PRIVATE ${_library} ${_libs})
    else()
      # Once per target: the normal build has one target (the regression test) using all groups.
      target_sources(${target} PRIVATE ${_sources})
      target_include_directories(${target} PRIVATE ${_includes})
      target_link_libraries(${target} PRIVATE ${_libs})
    endif()
  endforeach()
endfunction()
