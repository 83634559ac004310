# One place that finds every dependency. A missing one is a configure error naming the
# Debian 12 package to install (scripts/setup.sh installs them all).
find_package(PkgConfig REQUIRED)

function(colorlab_require_pkg name module debian_pkg)
  pkg_check_modules(${name} IMPORTED_TARGET GLOBAL ${module})
  if(NOT ${name}_FOUND)
    message(FATAL_ERROR "colorlab needs ${module}: apt-get install ${debian_pkg} (or run scripts/setup.sh)")
  endif()
endfunction()

function(colorlab_require_header var header debian_pkg)
  find_path(${var} ${header})
  if(NOT ${var})
    message(FATAL_ERROR "colorlab needs ${header}: apt-get install ${debian_pkg} (or run scripts/setup.sh)")
  endif()
endfunction()

find_package(Threads REQUIRED)

find_package(Boost 1.74 QUIET)
if(NOT Boost_FOUND)
  message(FATAL_ERROR "colorlab needs Boost (Asio, Beast): apt-get install libboost-dev")
endif()

find_package(SQLite3 QUIET)
if(NOT SQLite3_FOUND)
  message(FATAL_ERROR "colorlab needs SQLite3: apt-get install libsqlite3-dev")
endif()

find_package(Eigen3 3.3 QUIET NO_MODULE)
if(NOT Eigen3_FOUND)
  message(FATAL_ERROR "colorlab needs Eigen3: apt-get install libeigen3-dev")
endif()

find_package(nlohmann_json 3.10 QUIET)
if(NOT nlohmann_json_FOUND)
  message(FATAL_ERROR "colorlab needs nlohmann-json: apt-get install nlohmann-json3-dev")
endif()

find_package(CLI11 QUIET)
if(NOT CLI11_FOUND)
  colorlab_require_header(CLI11_INCLUDE_DIR CLI/CLI.hpp libcli11-dev)
  add_library(CLI11::CLI11 INTERFACE IMPORTED GLOBAL)
  target_include_directories(CLI11::CLI11 INTERFACE ${CLI11_INCLUDE_DIR})
endif()

# TLS for listeners beyond loopback, API keys' hashes and the blob store's content addresses.
find_package(OpenSSL QUIET COMPONENTS SSL Crypto)
if(NOT OpenSSL_FOUND)
  message(FATAL_ERROR "colorlab needs OpenSSL: apt-get install libssl-dev")
endif()

colorlab_require_pkg(TOMLPP tomlplusplus libtomlplusplus-dev)
colorlab_require_pkg(LIBSERIALPORT libserialport libserialport-dev)
colorlab_require_pkg(HIDAPI hidapi-hidraw libhidapi-dev)
colorlab_require_pkg(LIBUSB libusb-1.0 libusb-1.0-0-dev)
colorlab_require_pkg(LIBRAW libraw libraw-dev)
colorlab_require_pkg(ARAVIS aravis-0.8 libaravis-dev)
colorlab_require_pkg(GPHOTO2 libgphoto2 libgphoto2-dev)
colorlab_require_pkg(LCMS2 lcms2 liblcms2-dev)
colorlab_require_pkg(LUA lua5.4 liblua5.4-dev)
colorlab_require_pkg(LIBTIFF libtiff-4 libtiff-dev)
colorlab_require_pkg(SYSTEMD libsystemd libsystemd-dev)
# colorlabd's webhook notifications ([notify]).
colorlab_require_pkg(CURL libcurl libcurl4-openssl-dev)
# colorlab-ship's central catalog (fleet/).
colorlab_require_pkg(LIBPQ libpq libpq-dev)

# Asio on Boost 1.74 + GCC 12 in C++20 uses std::exchange without including <utility>.
add_library(colorlab_asio INTERFACE)
target_link_libraries(colorlab_asio INTERFACE Boost::headers Threads::Threads)
# GCC 12 misreports Asio coroutine frames as mismatched new/delete (a known false positive).
target_compile_options(colorlab_asio INTERFACE -include utility -Wno-mismatched-new-delete)
target_compile_definitions(colorlab_asio INTERFACE BOOST_ASIO_NO_DEPRECATED BOOST_BEAST_USE_STD_STRING_VIEW)

if(COLORLAB_BUILD_TESTS)
  find_package(GTest QUIET)
  if(NOT GTest_FOUND)
    message(FATAL_ERROR "colorlab's tests need GoogleTest: apt-get install libgtest-dev libgmock-dev")
  endif()
endif()
if(COLORLAB_BUILD_BENCH)
  find_package(benchmark QUIET)
  if(NOT benchmark_FOUND)
    message(FATAL_ERROR "colorlab's benchmarks need Google Benchmark: apt-get install libbenchmark-dev")
  endif()
endif()
