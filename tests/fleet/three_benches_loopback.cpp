#include "three_benches_loopback.hpp"

#include <arpa/inet.h>
#include <net/if.h>
#include <netinet/in.h>
#include <sched.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace colorlab::fleet_test {

namespace {

std::string failed(const std::string& what) {
  return what + ": " + std::strerror(errno) +
         " (the three-bench test runs as root, like CI, to give each simulated lab its own loopback address)";
}

// Legacy alias ioctls ("lo:N") rather than iproute2, which a fresh Debian 12 container may lack.
std::string set_address(int sock, const std::string& label, const std::string& address) {
  ifreq req{};
  std::strncpy(req.ifr_name, label.c_str(), IFNAMSIZ - 1);
  auto* in = reinterpret_cast<sockaddr_in*>(&req.ifr_addr);
  in->sin_family = AF_INET;
  if (::inet_pton(AF_INET, address.c_str(), &in->sin_addr) != 1) return "not an IPv4 address: " + address;
  if (::ioctl(sock, SIOCSIFADDR, &req) != 0) return failed("cannot give " + label + " the address " + address);
  ifreq mask{};
  std::strncpy(mask.ifr_name, label.c_str(), IFNAMSIZ - 1);
  auto* m = reinterpret_cast<sockaddr_in*>(&mask.ifr_netmask);
  m->sin_family = AF_INET;
  ::inet_pton(AF_INET, "255.0.0.0", &m->sin_addr);
  if (::ioctl(sock, SIOCSIFNETMASK, &mask) != 0) return failed("cannot set " + label + "'s netmask");
  return {};
}

}  // namespace

std::string enter_private_loopback(const std::vector<std::string>& extra_addresses) {
  if (::unshare(CLONE_NEWNET) != 0) return failed("cannot enter a private network namespace (unshare)");
  const int sock = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (sock < 0) return failed("socket");
  std::string error;
  ifreq lo{};
  std::strncpy(lo.ifr_name, "lo", IFNAMSIZ - 1);
  if (::ioctl(sock, SIOCGIFFLAGS, &lo) != 0) {
    error = failed("cannot read loopback's flags");
  } else {
    lo.ifr_flags = static_cast<short>(lo.ifr_flags | IFF_UP);
    if (::ioctl(sock, SIOCSIFFLAGS, &lo) != 0) error = failed("cannot bring loopback up");
  }
  for (std::size_t i = 0; error.empty() && i < extra_addresses.size(); ++i) {
    error = set_address(sock, "lo:" + std::to_string(i + 1), extra_addresses[i]);
  }
  ::close(sock);
  return error;
}

}  // namespace colorlab::fleet_test
