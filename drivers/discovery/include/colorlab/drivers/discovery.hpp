#pragma once
// Which instruments are plugged in, and which ones came or went since the last look. Real serial
// ports come from libserialport with their USB VID/PID/serial; relay boards from hidapi. Built-in
// rules recognise the Enttec DMX USB Pro and dcttech relay boards; RS-232 instruments behind
// generic USB-serial adapters are named by config rules that match the adapter's VID/PID/serial
// (stable across plug order) or give an explicit port. Sources are injectable for tests.
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "colorlab/wire/hid_transport.hpp"
#include "colorlab/drivers/port_enumeration.hpp"

namespace colorlab::drivers {

struct DiscoveryRule {
  std::string id;    // instrument id to report
  std::string kind;  // factory kind: "spectrolino", "ls110", "dmx", "hidrelay"
  // Either an explicit port (present while the path exists; ptys and symlinks allowed) ...
  std::string port;
  // ... or a USB match; unset fields match anything, but at least one must be set.
  std::optional<int> usb_vid;
  std::optional<int> usb_pid;
  std::string usb_serial;
};

struct DiscoveredInstrument {
  std::string id;  // from a rule, else "<kind>-<serial or path>"
  std::string kind;
  std::string port;         // device path to open
  std::string stable_port;  // /dev/serial/by-id/… link to it, when udev made one
  std::optional<int> usb_vid, usb_pid;
  std::string usb_serial;
  std::string product;
  bool from_rule = false;
  bool operator==(const DiscoveredInstrument&) const = default;
};

struct DiscoveryChange {
  bool added = false;  // false: removed
  DiscoveredInstrument instrument;
};

class Discovery {
 public:
  struct Sources {
    std::function<std::vector<SerialPortInfo>()> serial_ports = enumerate_serial_ports;
    std::function<std::vector<HidDeviceInfo>()> relay_boards;  // default: hidapi enumeration
    std::function<bool(const std::string&)> path_exists;       // default: std::filesystem::exists
    std::string by_id_dir = "/dev/serial/by-id";
  };

  // Throws Error{bad_parameter} for a rule with no id/kind or with neither port nor USB match.
  explicit Discovery(std::vector<DiscoveryRule> rules);
  Discovery(std::vector<DiscoveryRule> rules, Sources sources);

  // Everything present now, rules first; ports no rule or built-in claims are left out.
  std::vector<DiscoveredInstrument> scan() const;
  // Scans and returns what was added or removed since the previous poll (the first poll reports all).
  std::vector<DiscoveryChange> poll();
  const std::vector<DiscoveredInstrument>& present() const { return present_; }

  using Listener = std::function<void(const DiscoveryChange&)>;
  int subscribe(Listener listener);
  void unsubscribe(int token);

 private:
  std::vector<DiscoveryRule> rules_;
  Sources sources_;
  std::vector<DiscoveredInstrument> present_;
  std::map<int, Listener> listeners_;
  int next_token_ = 1;
};

}  // namespace colorlab::drivers
