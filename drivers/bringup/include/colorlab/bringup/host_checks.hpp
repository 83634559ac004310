#pragma once
// What the host offers before any byte is sent: serial ports with their USB identity and stable
// /dev/serial/by-id names (libserialport, udev's links), USB devices from sysfs with the device
// node's owner and mode, whether this user may open each, the colorlab group, and whether
// colorlab's udev rules are where udevd reads them. Paths are injectable for the tests.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace colorlab::bringup {

struct NodeAccess {
  std::string path;
  std::string owner, group;
  std::string mode;  // "crw-rw----"
  bool readable_writable = false;
  std::string problem;  // empty when this user may open it
  std::string hint;
};

// Owner, group, mode and whether this process may open `path` read-write, with a hint naming the
// group to join (or the udev rules to install) when it may not.
NodeAccess check_access(const std::string& path);

struct HostPaths {
  std::vector<std::string> udev_rule_dirs{"/etc/udev/rules.d", "/run/udev/rules.d", "/usr/lib/udev/rules.d",
                                          "/lib/udev/rules.d", "/usr/local/lib/udev/rules.d"};
  std::string rules_file = "70-colorlab.rules";
  std::string sysfs_usb = "/sys/bus/usb/devices";
  std::string by_id_dir = "/dev/serial/by-id";
  std::string dev_bus_usb = "/dev/bus/usb";
};

// The known instrument a USB VID:PID (and product string) belongs to, or empty.
std::string known_usb_device(int vid, int pid, const std::string& product);

nlohmann::json host_identity();                           // user, uid, groups, the colorlab group
nlohmann::json udev_rules_state(const HostPaths& paths);  // installed where, read by udevd or not
nlohmann::json serial_ports(const HostPaths& paths);      // libserialport's list with by-id links and access
nlohmann::json usb_devices(const HostPaths& paths);       // sysfs, each with its /dev/bus/usb node's access
// dcttech boards by hidapi, each with its hidraw node's access
nlohmann::json relay_boards();

}  // namespace colorlab::bringup
