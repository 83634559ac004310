#include "colorlab/bringup/host_checks.hpp"

#include <grp.h>
#include <pwd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "colorlab/drivers/hidapi_transport.hpp"
#include "colorlab/drivers/port_enumeration.hpp"

namespace colorlab::bringup {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string group_name(gid_t gid) {
  if (auto* g = ::getgrgid(gid)) return g->gr_name;
  return std::to_string(gid);
}

std::string user_name(uid_t uid) {
  if (auto* p = ::getpwuid(uid)) return p->pw_name;
  return std::to_string(uid);
}

std::vector<gid_t> my_groups() {
  int n = ::getgroups(0, nullptr);
  std::vector<gid_t> g(static_cast<std::size_t>(std::max(n, 0)));
  if (n > 0) n = ::getgroups(n, g.data());
  g.resize(static_cast<std::size_t>(std::max(n, 0)));
  g.push_back(::getegid());
  return g;
}

std::string mode_string(mode_t m) {
  std::string s = S_ISCHR(m) ? "c" : S_ISDIR(m) ? "d"
                                 : S_ISLNK(m)   ? "l"
                                                : "-";
  const char* rwx = "rwxrwxrwx";
  for (int i = 0; i < 9; ++i) s += (m & (0400 >> i)) ? rwx[i] : '-';
  return s;
}

std::string read_attr(const fs::path& dir, const char* name) {
  std::ifstream in(dir / name);
  std::string v;
  std::getline(in, v);
  return v;
}

std::string by_id_link(const std::string& by_id_dir, const std::string& path) {
  std::error_code ec;
  if (!fs::is_directory(by_id_dir, ec)) return {};
  auto target = fs::weakly_canonical(path, ec);
  for (const auto& e : fs::directory_iterator(by_id_dir, ec)) {
    std::error_code ec2;
    if (fs::weakly_canonical(e.path(), ec2) == target && !ec2) return e.path().string();
  }
  return {};
}

json access_json(const NodeAccess& a) {
  json j{{"path", a.path}, {"owner", a.owner}, {"group", a.group}, {"mode", a.mode}, {"access", a.readable_writable}};
  if (!a.problem.empty()) j["problem"] = a.problem;
  if (!a.hint.empty()) j["hint"] = a.hint;
  return j;
}

}  // namespace

NodeAccess check_access(const std::string& path) {
  NodeAccess a;
  a.path = path;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    a.problem = "does not exist";
    a.hint = "unplugged, or udev has not created the node yet";
    return a;
  }
  a.owner = user_name(st.st_uid);
  a.group = group_name(st.st_gid);
  a.mode = mode_string(st.st_mode);
  a.readable_writable = ::access(path.c_str(), R_OK | W_OK) == 0;
  if (!a.readable_writable) {
    auto groups = my_groups();
    bool member = std::find(groups.begin(), groups.end(), st.st_gid) != groups.end();
    a.problem = "this user (" + user_name(::geteuid()) + ") may not open it read-write";
    if ((st.st_mode & S_IRWXG) == (S_IRGRP | S_IWGRP) && !member) {
      a.hint = "add the user to group '" + a.group + "' (sudo usermod -aG " + a.group + " " + user_name(::geteuid()) +
               ", then log in again); colorlabd runs as user colorlab, which is in group colorlab";
    } else if (member) {
      a.hint = "the group '" + a.group + "' lacks rw on it: install colorlab's udev rules (MODE=0660, GROUP=colorlab) and replug";
    } else {
      a.hint = "install colorlab's udev rules (GROUP=colorlab, MODE=0660) and replug, or join the group that owns it";
    }
  }
  return a;
}

std::string known_usb_device(int vid, int pid, const std::string& product) {
  auto has = [&](const char* s) {
    std::string p = product;
    std::transform(p.begin(), p.end(), p.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    return p.find(s) != std::string::npos;
  };
  if (vid == 0x0403 && pid == 0x6001 && has("DMX USB PRO")) return "Enttec DMX USB Pro";
  if (vid == 0x0403 && pid == 0x6001) return "FTDI FT232R serial adapter (LS-110 or Spectrolino cable)";
  if (vid == 0x067b && pid == 0x2303) return "Prolific PL2303 serial adapter (LS-110 or Spectrolino cable)";
  if (vid == 0x16c0 && pid == 0x05df && has("USBRELAY")) return "dcttech USB HID relay board";
  if (vid == 0x04a9 && pid == 0x3077) return "Canon EOS 20D (gphoto2)";
  return {};
}

json host_identity() {
  json groups = json::array();
  for (auto g : my_groups()) {
    auto name = group_name(g);
    if (std::find(groups.begin(), groups.end(), name) == groups.end()) groups.push_back(name);
  }
  json j{{"user", user_name(::geteuid())}, {"uid", ::geteuid()}, {"groups", groups}};
  auto* cg = ::getgrnam("colorlab");
  j["colorlab_group"] = cg != nullptr;
  if (!cg) {
    j["colorlab_group_hint"] = "the group colorlab does not exist: install colorlab (its sysusers entry makes it: "
                               "systemd-sysusers) so the udev rules can give it the instruments";
  }
  return j;
}

json udev_rules_state(const HostPaths& paths) {
  json found = json::array();
  for (const auto& dir : paths.udev_rule_dirs) {
    std::error_code ec;
    auto p = fs::path(dir) / paths.rules_file;
    if (fs::exists(p, ec)) found.push_back(p.string());
  }
  json j{{"file", paths.rules_file}, {"found", found}};
  // udevd reads /etc, /run, /usr/lib and /lib; a copy only under /usr/local (cmake --install's
  // default prefix) is never read.
  bool read_by_udev = std::any_of(found.begin(), found.end(), [](const json& p) {
    return p.get<std::string>().rfind("/usr/local/", 0) != 0;
  });
  j["installed"] = read_by_udev;
  if (!read_by_udev) {
    j["hint"] = found.empty()
                    ? "colorlab's udev rules are not installed: sudo cp systemd/70-colorlab.rules /etc/udev/rules.d/ && "
                      "sudo udevadm control --reload && sudo udevadm trigger (or install the colorlab package)"
                    : "the rules are only under /usr/local, which udevd does not read: copy them to /etc/udev/rules.d/ "
                      "and run udevadm control --reload && udevadm trigger";
  }
  return j;
}

json serial_ports(const HostPaths& paths) {
  json out = json::array();
  for (const auto& p : drivers::enumerate_serial_ports()) {
    json j{{"path", p.path}, {"transport", p.transport}, {"description", p.description}};
    if (p.usb_vid) j["usb_vid"] = *p.usb_vid;
    if (p.usb_pid) j["usb_pid"] = *p.usb_pid;
    if (!p.usb_serial.empty()) j["usb_serial"] = p.usb_serial;
    if (!p.usb_manufacturer.empty()) j["usb_manufacturer"] = p.usb_manufacturer;
    if (!p.usb_product.empty()) j["usb_product"] = p.usb_product;
    if (p.usb_vid && p.usb_pid) {
      auto known = known_usb_device(*p.usb_vid, *p.usb_pid, p.usb_product);
      if (!known.empty()) j["known_as"] = known;
    }
    auto link = by_id_link(paths.by_id_dir, p.path);
    if (!link.empty()) j["by_id"] = link;
    j["node"] = access_json(check_access(p.path));
    out.push_back(j);
  }
  return out;
}

json usb_devices(const HostPaths& paths) {
  json out = json::array();
  std::error_code ec;
  if (!fs::is_directory(paths.sysfs_usb, ec)) return out;
  std::vector<fs::path> dirs;
  for (const auto& e : fs::directory_iterator(paths.sysfs_usb, ec)) {
    // Devices, not interfaces ("1-1:1.0") or root hubs' own interfaces.
    if (e.path().filename().string().find(':') == std::string::npos) dirs.push_back(e.path());
  }
  std::sort(dirs.begin(), dirs.end());
  for (const auto& d : dirs) {
    auto vid_s = read_attr(d, "idVendor");
    auto pid_s = read_attr(d, "idProduct");
    if (vid_s.empty() || pid_s.empty()) continue;
    int vid = std::stoi(vid_s, nullptr, 16), pid = std::stoi(pid_s, nullptr, 16);
    json j{
        {"sysfs", d.filename().string()},
        {"usb_vid", vid},
        {"usb_pid", pid},
        {"manufacturer", read_attr(d, "manufacturer")},
        {"product", read_attr(d, "product")},
        {"serial", read_attr(d, "serial")},
    };
    auto known = known_usb_device(vid, pid, j["product"].get<std::string>());
    if (!known.empty()) j["known_as"] = known;
    auto bus = read_attr(d, "busnum"), dev = read_attr(d, "devnum");
    if (!bus.empty() && !dev.empty()) {
      char node[64];
      std::snprintf(node, sizeof node, "%s/%03d/%03d", paths.dev_bus_usb.c_str(), std::stoi(bus), std::stoi(dev));
      // Only a camera is opened through this node (libgphoto2); serial adapters through their tty,
      // relay boards through hidraw (listed with those), hubs and keyboards not at all.
      if (known.find("gphoto2") != std::string::npos) {
        j["node"] = access_json(check_access(node));
      } else {
        j["node_path"] = node;
      }
    }
    out.push_back(j);
  }
  return out;
}

}  // namespace colorlab::bringup

namespace colorlab::bringup {

json relay_boards() {
  json out = json::array();
  for (const auto& b : drivers::enumerate_relay_boards()) {
    out.push_back({
        {"path", b.path},
        {"usb_vid", b.vendor_id},
        {"usb_pid", b.product_id},
        {"manufacturer", b.manufacturer},
        {"product", b.product},
        {"serial", b.serial},
        {"node", access_json(check_access(b.path))},
    });
  }
  return out;
}

}  // namespace colorlab::bringup
