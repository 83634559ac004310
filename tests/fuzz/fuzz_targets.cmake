# The libFuzzer build (COLORLAB_FUZZ=ON, `cmake --preset fuzz`): included by the top-level
# CMakeLists.txt in place of the whole project, so a clang + ASan + UBSan build compiles only what
# the parsers need — the small libraries they live in, or, where the library around a parser drags
# in devices and databases, just the parser's own source files. Every target is <name>_fuzz in
# build-fuzz/fuzz/; `cmake --build build-fuzz --target fuzz_all` builds them all.
if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "COLORLAB_FUZZ needs clang's libFuzzer: cmake --preset fuzz (apt-get install clang libfuzzer-14-dev libclang-rt-14-dev)")
endif()

# Coverage for libFuzzer and both sanitizers on the parsers and the libraries they live in; the
# fuzzer's main only on the targets. UBSan stops at the first report so it counts as a crash.
set(COLORLAB_FUZZ_FLAGS -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined
                        -fno-omit-frame-pointer -O1)
add_link_options(-fsanitize=address,undefined)
# Boost 1.74's Asio looks for clang's coroutines in <experimental/coroutine>, which libstdc++ lacks;
# clang 14 has C++20 coroutines in <coroutine> (as GCC, where Asio finds them), so say so.
add_compile_definitions(BOOST_ASIO_HAS_CO_AWAIT=1)
# Boost's own assertions off, as in the shipped (NDEBUG) build: Beast 1.74 asserts `n >= 5` in its chunk
# parser where a final chunk `0\r\n` can leave fewer bytes, and the code after it copes (boostorg/beast
# PR #2861 relaxed the assertion). ASan still checks every byte the parser reads.
add_compile_definitions(BOOST_DISABLE_ASSERTS)

include(CheckCXXSourceCompiles)
set(CMAKE_REQUIRED_LINK_OPTIONS -fsanitize=fuzzer)
check_cxx_source_compiles([[
#include <cstddef>
#include <cstdint>
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t*, std::size_t) { return 0; }
]] COLORLAB_HAVE_LIBFUZZER)
unset(CMAKE_REQUIRED_LINK_OPTIONS)
if(NOT COLORLAB_HAVE_LIBFUZZER)
  message(FATAL_ERROR "clang cannot link -fsanitize=fuzzer: apt-get install libclang-rt-14-dev (clang only recommends it)")
endif()

find_package(OpenSSL REQUIRED COMPONENTS Crypto)
add_subdirectory(core)
add_subdirectory(protocol)
add_subdirectory(drivers/wire)
foreach(lib colorlab_core colorlab_protocol colorlab_wire_protocols)
  target_compile_options(${lib} PRIVATE ${COLORLAB_FUZZ_FLAGS})
endforeach()
# The colour science behind the `lab.analysis` functions a campaign script's top level could call: not
# a parser and not fuzzed here, so built plain and unoptimised — Eigen at -O1 under the sanitizers
# would be most of this build's time (ASan's allocator still sees its memory).
add_subdirectory(analysis)
target_compile_options(colorlab_analysis PRIVATE -O0 -g0)
# The lab a campaign script's `lab` table is built from (the registry of calls names the live lab's and
# the dry run's handlers) and the procedures behind lab_api's analysis functions: linked by the campaign
# targets, not fuzzed, so built plain like analysis. drivers/camera also defines the test-only simulated
# camera, which links sim/camera: an empty stand-in here, as nothing in this build links that target, and
# it is left out of `all`, which it could not compile without sim/camera's headers (a plain
# `cmake --build build-fuzz` failed on it; the preset builds only fuzz_all).
add_subdirectory(drivers/core)
add_library(colorlab::sim_camera INTERFACE IMPORTED)
add_subdirectory(drivers/camera)
set_target_properties(colorlab_drivers_simulated_camera PROPERTIES EXCLUDE_FROM_ALL TRUE)
add_subdirectory(campaigns)
# colorlabd's configuration reads [cabinet] through verify/scene (its parser and validation): linked by the
# daemon_config group, not fuzzed here, so built plain like the lab.
add_subdirectory(verify/scene)
foreach(lib colorlab_drivers_core colorlab_drivers_camera colorlab_chart_locate colorlab_campaign_lab
            colorlab_campaign_procedures colorlab_verify_scene)
  target_compile_options(${lib} PRIVATE -O0 -g0)
endforeach()

# Each parser source group (fuzz_parsers.cmake) is one object library with these flags, compiled once
# and linked by every target that needs it.
set(COLORLAB_FUZZ_GROUP_OPTIONS ${COLORLAB_FUZZ_FLAGS})
include(${CMAKE_CURRENT_LIST_DIR}/fuzz_parsers.cmake)
add_custom_target(fuzz_all)
foreach(name IN LISTS COLORLAB_FUZZ_TARGETS)
  add_executable(${name}_fuzz ${CMAKE_CURRENT_LIST_DIR}/${name}_fuzz.cpp)
  set_target_properties(${name}_fuzz PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/fuzz)
  target_include_directories(${name}_fuzz PRIVATE ${CMAKE_CURRENT_LIST_DIR})
  target_compile_definitions(${name}_fuzz PRIVATE COLORLAB_LIBFUZZER COLORLAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  target_compile_options(${name}_fuzz PRIVATE ${COLORLAB_FUZZ_FLAGS})
  target_link_options(${name}_fuzz PRIVATE -fsanitize=fuzzer)
  colorlab_fuzz_parser(${name}_fuzz ${name})
  colorlab_warnings(${name}_fuzz)
  add_dependencies(fuzz_all ${name}_fuzz)
endforeach()
