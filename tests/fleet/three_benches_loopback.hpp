#pragma once
// Three simulated labs on one machine each need their own GigE Vision address, and Aravis's fake camera serves only
// an address an interface holds (127.0.0.2 is routed to loopback on Linux but held by none). The test therefore
// moves itself into a private network namespace before it starts anything: its own loopback, brought up, holding
// 127.0.0.1 plus the addresses asked for. Nothing on the host changes, and everything the test starts (PostgreSQL,
// Swift, the daemons and their labs, the agents) shares that loopback and none of the team's ports.
#include <string>
#include <vector>

namespace colorlab::fleet_test {

// Call first in main(), before any thread exists (unshare moves only the calling thread, and children inherit
// it). Returns "" on success, else what went wrong and what it needs (root: CAP_SYS_ADMIN and CAP_NET_ADMIN).
std::string enter_private_loopback(const std::vector<std::string>& extra_addresses);

}  // namespace colorlab::fleet_test
