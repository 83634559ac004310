#pragma once
// The one PostgreSQL + Swift pair of fleet_central_console_https_test, whose two files (central_console_test.cpp,
// ship_https_test.cpp) share it so the servers start once for the program.
#include "fleet_servers.hpp"

#ifndef COLORLAB_BIN_DIR
#error "COLORLAB_BIN_DIR must be defined by the build"
#endif

namespace colorlab::fleet_test {

inline SharedServers& web_tls_servers() {
  return shared_servers(std::filesystem::path(COLORLAB_BIN_DIR).parent_path() / "tests" / "fleet-web-tls-scratch",
                        "colorlab-web-tls-pg");
}

}  // namespace colorlab::fleet_test
