# What each fuzz target's parser is made of: its own source files (compiled into the target, so the
# libFuzzer build need not build the device- and database-laden library around a parser) and the
# small libraries it links. Shared by the libFuzzer build (fuzz_targets.cmake) and the normal build's
# regression test (CMakeLists.txt), so both run exactly the same parser code.
set(COLORLAB_FUZZ_TARGETS
  spectrolino_wire dmx_wire ls110_reply cgats csv pgm http_target http_request config_toml
  campaign_script campaign_params hid_socket simdslr_socket)

# colorlab_fuzz_parser(<cmake target> <fuzz target name>)
function(colorlab_fuzz_parser target name)
  set(s ${PROJECT_SOURCE_DIR})
  set(sources)
  set(includes)
  set(libs colorlab::core)
  if(name STREQUAL "spectrolino_wire" OR name STREQUAL "dmx_wire")
    list(APPEND libs colorlab::wire_protocols)
  elseif(name STREQUAL "ls110_reply")
    list(APPEND libs colorlab::wire_protocols)
  elseif(name STREQUAL "cgats" OR name STREQUAL "csv")
    list(APPEND sources ${s}/analysis/src/cgats.cpp ${s}/analysis/src/csv.cpp ${s}/analysis/src/csv_write.cpp)
    list(APPEND includes ${s}/analysis/include)
  elseif(name STREQUAL "pgm")
    list(APPEND sources ${s}/client/analyze/src/pgm_reader.cpp)
    list(APPEND includes ${s}/client/analyze/src)
  elseif(name STREQUAL "http_target" OR name STREQUAL "http_request")
    list(APPEND sources ${s}/daemon/http/src/message.cpp)
    list(APPEND includes ${s}/daemon/http/include)
    list(APPEND libs colorlab::protocol colorlab_asio)
  elseif(name STREQUAL "config_toml")
    list(APPEND sources ${s}/daemon/core/src/config.cpp)
    list(APPEND includes ${s}/daemon/core/include ${s}/drivers/factory/include ${s}/drivers/core/include)
    # toml++ is Debian's shared build, as colorlabd links it: its parser is not instrumented, so the
    # fuzzer is guided by config.cpp's branches alone (the seeds and dictionary give it valid TOML). Two
    # toml++ 3.3.0 bugs seen when it was compiled in under the sanitizers are upstream's: an assertion on a
    # table header such as `[)x]` (marzer/tomlplusplus PR #301; the shipped build answers a parse_error)
    # and an "unreachable" in its Unicode whitespace table (issues #190, #295; PR #305).
    list(APPEND libs colorlab::protocol colorlab_asio nlohmann_json::nlohmann_json PkgConfig::TOMLPP)
  elseif(name STREQUAL "campaign_script" OR name STREQUAL "campaign_params")
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
  elseif(name STREQUAL "hid_socket")
    list(APPEND sources ${s}/drivers/lamps/src/socket_hid_transport.cpp
         ${s}/drivers/core/src/unix_line_client.cpp)
    list(APPEND includes ${s}/drivers/lamps/include ${s}/drivers/core/include)
    list(APPEND libs colorlab::wire_protocols nlohmann_json::nlohmann_json Threads::Threads)
  elseif(name STREQUAL "simdslr_socket")
    # The driver with the Camera base class it derives from (worker thread, the capture pipeline's
    # LibRaw decoder, the gphoto2 driver's shutter labels and raw file names).
    foreach(f sim_dslr_camera camera camera_settings worker_thread raw_image raw_decoder gphoto2_camera)
      list(APPEND sources ${s}/drivers/camera/src/${f}.cpp)
    endforeach()
    list(APPEND sources ${s}/drivers/core/src/unix_line_client.cpp)
    list(APPEND includes ${s}/drivers/camera/include ${s}/drivers/core/include)
    list(APPEND libs nlohmann_json::nlohmann_json Threads::Threads PkgConfig::LIBRAW PkgConfig::GPHOTO2)
  else()
    message(FATAL_ERROR "colorlab_fuzz_parser: no parser named ${name}")
  endif()
  target_sources(${target} PRIVATE ${sources})
  target_include_directories(${target} PRIVATE ${includes})
  target_link_libraries(${target} PRIVATE ${libs})
endfunction()
