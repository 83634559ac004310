#include "colorlab/drivers/discovery.hpp"

#include <algorithm>
#include <filesystem>
#include <system_error>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/hidapi_transport.hpp"

namespace colorlab::drivers {

namespace fs = std::filesystem;

namespace {

constexpr int kFtdiVid = 0x0403, kFtdiFt232Pid = 0x6001;

bool contains_nocase(std::string hay, std::string needle) {
  auto lower = [](std::string s) {
    for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
  };
  return lower(std::move(hay)).find(lower(std::move(needle))) != std::string::npos;
}

bool matches(const DiscoveryRule& r, const SerialPortInfo& p) {
  if (!r.port.empty()) return false;
  if (r.usb_vid && p.usb_vid != r.usb_vid) return false;
  if (r.usb_pid && p.usb_pid != r.usb_pid) return false;
  if (!r.usb_serial.empty() && p.usb_serial != r.usb_serial) return false;
  return true;
}

std::string stable_link(const std::string& by_id_dir, const std::string& path) {
  std::error_code ec;
  if (!fs::is_directory(by_id_dir, ec)) return {};
  for (const auto& e : fs::directory_iterator(by_id_dir, ec)) {
    auto target = fs::weakly_canonical(e.path(), ec);
    if (!ec && target == fs::weakly_canonical(path, ec)) return e.path().string();
  }
  return {};
}

}  // namespace

Discovery::Discovery(std::vector<DiscoveryRule> rules) : Discovery(std::move(rules), Sources{}) {}

Discovery::Discovery(std::vector<DiscoveryRule> rules, Sources sources) : rules_(std::move(rules)), sources_(std::move(sources)) {
  if (!sources_.serial_ports) sources_.serial_ports = [] { return std::vector<SerialPortInfo>{}; };
  if (!sources_.relay_boards) sources_.relay_boards = enumerate_relay_boards;
  if (!sources_.path_exists) sources_.path_exists = [](const std::string& p) {
    std::error_code ec;
    return fs::exists(p, ec);
  };
  for (const auto& r : rules_) {
    if (r.id.empty() || r.kind.empty()) throw Error(ErrorClass::bad_parameter, "a discovery rule needs an id and a kind");
    if (r.port.empty() && !r.usb_vid && !r.usb_pid && r.usb_serial.empty()) {
      throw Error(ErrorClass::bad_parameter, "discovery rule '" + r.id + "' names neither a port nor a USB vid/pid/serial",
                  "plug-order names like /dev/ttyUSB0 change; match the adapter's USB serial instead");
    }
  }
}

std::vector<DiscoveredInstrument> Discovery::scan() const {
  std::vector<DiscoveredInstrument> out;
  auto ports = sources_.serial_ports();
  std::vector<bool> claimed(ports.size(), false);
  for (const auto& r : rules_) {
    if (!r.port.empty()) {
      if (!sources_.path_exists(r.port)) continue;
      DiscoveredInstrument d;
      d.id = r.id;
      d.kind = r.kind;
      d.port = r.port;
      d.from_rule = true;
      d.stable_port = stable_link(sources_.by_id_dir, r.port);
      out.push_back(std::move(d));
      for (std::size_t i = 0; i < ports.size(); ++i) claimed[i] = claimed[i] || ports[i].path == r.port;
      continue;
    }
    for (std::size_t i = 0; i < ports.size(); ++i) {
      if (claimed[i] || !matches(r, ports[i])) continue;
      claimed[i] = true;
      const auto& p = ports[i];
      out.push_back(DiscoveredInstrument{r.id, r.kind, p.path, stable_link(sources_.by_id_dir, p.path), p.usb_vid, p.usb_pid,
                                         p.usb_serial, p.usb_product, true});
      break;  // one rule, one instrument
    }
  }
  // Built-in: the DMX USB Pro is an FTDI FT232 whose product string names it.
  for (std::size_t i = 0; i < ports.size(); ++i) {
    const auto& p = ports[i];
    if (claimed[i] || p.usb_vid != kFtdiVid || p.usb_pid != kFtdiFt232Pid || !contains_nocase(p.usb_product, "DMX USB PRO")) continue;
    out.push_back(DiscoveredInstrument{"dmx-" + (p.usb_serial.empty() ? p.path : p.usb_serial), "dmx", p.path,
                                       stable_link(sources_.by_id_dir, p.path), p.usb_vid, p.usb_pid, p.usb_serial,
                                       p.usb_product, false});
  }
  for (const auto& b : sources_.relay_boards()) {
    DiscoveredInstrument d;
    d.id = "hidrelay-" + b.path.substr(b.path.find_last_of('/') + 1);
    d.kind = "hidrelay";
    d.port = b.path;
    d.usb_vid = b.vendor_id;
    d.usb_pid = b.product_id;
    d.usb_serial = b.serial;
    d.product = b.product;
    out.push_back(std::move(d));
  }
  return out;
}

std::vector<DiscoveryChange> Discovery::poll() {
  auto now = scan();
  std::vector<DiscoveryChange> changes;
  for (const auto& old : present_) {
    if (std::find(now.begin(), now.end(), old) == now.end()) changes.push_back({false, old});
  }
  for (const auto& cur : now) {
    if (std::find(present_.begin(), present_.end(), cur) == present_.end()) changes.push_back({true, cur});
  }
  present_ = std::move(now);
  auto listeners = listeners_;  // a listener may unsubscribe itself
  for (const auto& c : changes) {
    for (const auto& [_, l] : listeners) l(c);
  }
  return changes;
}

int Discovery::subscribe(Listener listener) {
  int t = next_token_++;
  listeners_[t] = std::move(listener);
  return t;
}

void Discovery::unsubscribe(int token) { listeners_.erase(token); }

}  // namespace colorlab::drivers
