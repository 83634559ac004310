#include "doctor_output.hpp"

#include <cstdio>
#include <sstream>

namespace colorlab::cli {

using nlohmann::json;

namespace {

std::string hex4(const json& v) {
  if (!v.is_number_integer()) return "????";
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04x", v.get<int>());
  return buf;
}

std::string text(const json& j, const char* key) {
  return j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : std::string();
}

void node_line(std::ostringstream& out, const json& node) {
  if (node.is_null()) return;
  out << "      node " << text(node, "path") << "  " << text(node, "mode") << " " << text(node, "owner") << ":" << text(node, "group");
  if (node.value("access", false)) {
    out << "  access ok\n";
  } else {
    out << "  NO ACCESS: " << text(node, "problem") << "\n";
    if (node.contains("hint")) out << "      hint: " << text(node, "hint") << "\n";
  }
}

const char* verdict_word(const std::string& v) {
  if (v == "identified") return "OK";
  if (v == "wrong_instrument") return "WRONG INSTRUMENT";
  if (v == "unknown_protocol") return "UNKNOWN PROTOCOL";
  if (v == "silent") return "SILENT";
  if (v == "cannot_open") return "CANNOT OPEN";
  return "FAILED";
}

std::string show_value(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_array() && v.size() > 6) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "[%zu values: %.4g … %.4g]", v.size(), v.front().get<double>(), v.back().get<double>());
    return buf;
  }
  return v.dump();
}

}  // namespace

std::string render_report(const json& r) {
  std::ostringstream out;
  out << "colorlab doctor — nothing is measured, moved or lit without --measure, --yes or a yes at the prompt\n";
  if (r.contains("host")) {
    const auto& h = r["host"];
    out << "\nHost\n  user " << text(h, "user") << " (uid " << h.value("uid", -1) << "), groups:";
    for (const auto& g : h["groups"]) out << " " << g.get<std::string>();
    out << "\n  group colorlab: " << (h.value("colorlab_group", false) ? "exists" : "MISSING") << "\n";
    if (h.contains("colorlab_group_hint")) out << "    hint: " << text(h, "colorlab_group_hint") << "\n";
  }
  if (r.contains("udev_rules")) {
    const auto& u = r["udev_rules"];
    out << "  udev rules " << text(u, "file") << ": ";
    if (u.value("installed", false)) {
      out << "installed";
      for (const auto& f : u["found"]) out << " " << f.get<std::string>();
      out << "\n";
    } else {
      out << "NOT INSTALLED where udevd reads them\n    hint: " << text(u, "hint") << "\n";
    }
  }
  if (r.contains("serial_ports")) {
    out << "\nSerial ports (libserialport; pseudo-terminals are not listed)\n";
    if (r["serial_ports"].empty()) out << "  none\n";
    for (const auto& p : r["serial_ports"]) {
      out << "  " << text(p, "path") << "  " << text(p, "transport");
      if (p.contains("usb_vid")) out << " " << hex4(p["usb_vid"]) << ":" << hex4(p["usb_pid"]);
      if (p.contains("usb_serial")) out << " serial " << text(p, "usb_serial");
      if (p.contains("usb_product")) out << " \"" << text(p, "usb_product") << "\"";
      if (p.contains("known_as")) out << "  = " << text(p, "known_as");
      out << "\n";
      if (p.contains("by_id")) out << "      by-id " << text(p, "by_id") << "\n";
      node_line(out, p.value("node", json()));
    }
  }
  if (r.contains("usb_devices")) {
    out << "\nUSB devices (sysfs)\n";
    if (r["usb_devices"].empty()) out << "  none\n";
    for (const auto& d : r["usb_devices"]) {
      out << "  " << text(d, "sysfs") << "  " << hex4(d["usb_vid"]) << ":" << hex4(d["usb_pid"]) << " " << text(d, "manufacturer")
          << " " << text(d, "product");
      if (!text(d, "serial").empty()) out << " serial " << text(d, "serial");
      if (d.contains("known_as")) out << "  = " << text(d, "known_as");
      out << "\n";
      node_line(out, d.value("node", json()));
    }
  }
  if (r.contains("relay_boards") && !r["relay_boards"].empty()) {
    out << "\nRelay boards (hidapi)\n";
    for (const auto& b : r["relay_boards"]) {
      out << "  " << text(b, "path") << "  " << text(b, "manufacturer") << " " << text(b, "product") << "\n";
      node_line(out, b.value("node", json()));
    }
  }
  if (r.contains("gige_discovered")) {
    out << "\nGigE Vision cameras (Aravis discovery)\n";
    if (r["gige_discovered"].empty()) out << "  none answered the broadcast\n";
    for (const auto& c : r["gige_discovered"]) {
      out << "  " << text(c, "id") << "  " << text(c, "vendor") << " " << text(c, "model") << " serial " << text(c, "serial")
          << " at " << text(c, "address") << " (" << text(c, "protocol") << ")\n";
    }
  }
  out << "\nInstruments\n";
  if (r.value("ports", json::array()).empty() && r.value("cameras", json::array()).empty() &&
      r.value("relays", json::array()).empty()) {
    out << "  no port examined (no known instrument adapter found; name ports with --port PATH[=KIND])\n";
  }
  for (const auto& p : r.value("ports", json::array())) {
    out << "  " << text(p, "port") << "  " << verdict_word(text(p, "verdict"));
    if (p.contains("phase")) out << "  (" << text(p, "phase") << ")";
    char secs[32];
    std::snprintf(secs, sizeof secs, "  %.2f s", p.value("seconds", 0.0));
    out << secs << "\n    " << text(p, "message") << "\n";
    if (p.contains("hint")) out << "    hint: " << text(p, "hint") << "\n";
    const auto& id = p["identity"];
    if (!id.empty()) {
      out << "    identity:";
      for (const auto& [k, v] : id.items()) out << " " << k << "=" << show_value(v);
      out << "\n";
    }
    const auto& cal = p["calibration"];
    if (!cal.empty()) out << "    calibration: " << (cal.contains("state") ? text(cal, "state") + " — " : "") << text(cal, "detail") << "\n";
    if (p.value("measured", false)) {
      out << "    reading:";
      for (const auto& [k, v] : p["decoded"].items()) {
        if (k != "verdict" && k != "kind") out << " " << k << "=" << show_value(v);
      }
      out << "\n";
    }
    if (p.contains("operator_confirmed")) {
      out << "    operator confirmed:";
      for (const auto& [k, v] : p["operator_confirmed"].items()) out << " " << k << "=" << show_value(v["value"]);
      out << "\n";
    }
    if (p.value("operator_disagrees", false)) {
      out << "    THE OPERATOR READS A DIFFERENT VALUE than colorlab decoded: the transcript keeps the operator's, so its "
             "replay test fails until the driver agrees\n";
    }
    if (p.contains("transcript")) out << "    transcript: " << text(p, "transcript") << "\n";
  }
  for (const auto& c : r.value("cameras", json::array())) {
    out << "  " << text(c, "address") << "  " << verdict_word(text(c, "verdict")) << "  (GigE Vision)\n    " << text(c, "message") << "\n";
    if (c.contains("hint")) out << "    hint: " << text(c, "hint") << "\n";
    if (c.contains("serial")) out << "    identity: serial=" << text(c, "serial") << "\n";
    if (c.contains("calibration")) out << "    calibration: " << text(c["calibration"], "detail") << "\n";
  }
  for (const auto& b : r.value("relays", json::array())) {
    out << "  " << text(b, "where") << "  " << verdict_word(text(b, "verdict")) << "  (relay board)\n    " << text(b, "message") << "\n";
    if (b.contains("hint")) out << "    hint: " << text(b, "hint") << "\n";
  }
  if (r.contains("readings")) out << "\n"
                                  << text(r, "readings") << "\n";
  if (r.value("interim", false)) {
    out << "\nIdentification done; nothing has been measured.\n";
    return out.str();
  }
  char secs[48];
  std::snprintf(secs, sizeof secs, "%.2f s", r.value("seconds", 0.0));
  out << "\n"
      << (r.value("ok", false) ? "All examined instruments answered as expected" : "PROBLEMS FOUND (see above)") << " in "
      << secs << "; exit code " << r.value("exit_code", 0) << "\n";
  return out.str();
}

}  // namespace colorlab::cli
