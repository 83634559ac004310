#pragma once
// The API's one route table (src/route_table.cpp): method, path pattern, scope, placement and
// handler of every /v1 route. The router, the access check and the thread placement read it; a test
// checks docs/API.md's route list against it.
#include <span>

#include "colorlab/api/route.hpp"

namespace colorlab::daemon {

std::span<const Route> route_table();

}  // namespace colorlab::daemon
