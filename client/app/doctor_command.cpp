#include "doctor_command.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <memory>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/io_context.hpp>

#include "colorlab/bringup/examine.hpp"
#include "colorlab/bringup/gige_listing.hpp"
#include "colorlab/bringup/host_checks.hpp"
#include "colorlab/bringup/relay_check.hpp"
#include "colorlab/bringup/transcript_file.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/drivers/hidapi_transport.hpp"
#include "colorlab/drivers/port_enumeration.hpp"
#include "doctor_output.hpp"

namespace colorlab::cli {

namespace fs = std::filesystem;
namespace bu = colorlab::bringup;
using nlohmann::json;

namespace {

struct DoctorOptions {
  std::vector<std::string> ports;    // PATH or PATH=KIND
  std::vector<std::string> cameras;  // addresses
  std::vector<std::string> relays;   // hidraw paths or unix:PATH
  bool all_ports = false;
  bool no_gige = false;
  bool no_host = false;
  bool measure = false;
  bool yes = false;
  std::string record;
  bool no_record = false;
};

struct PortPlan {
  std::string path;
  std::string expect;
};

std::vector<PortPlan> plan_ports(const DoctorOptions& o, json& skipped) {
  std::vector<PortPlan> out;
  for (const auto& p : o.ports) {
    auto eq = p.rfind('=');
    PortPlan plan{p, ""};
    if (eq != std::string::npos) {
      plan = {p.substr(0, eq), p.substr(eq + 1)};
      if (!bu::is_serial_kind(plan.expect)) {
        throw Error(ErrorClass::bad_parameter, "--port " + p + ": unknown instrument kind '" + plan.expect + "'",
                    "give --port PATH or --port PATH=KIND with KIND one of dmx, ls110, spectrolino");
      }
    }
    if (plan.path.empty()) throw Error(ErrorClass::bad_parameter, "--port " + p + ": no path", "e.g. --port /dev/ttyUSB0=ls110");
    out.push_back(plan);
  }
  if (!o.ports.empty()) return out;
  // Without --port: the USB serial ports whose adapter an instrument of the lab comes on; other
  // ports (a modem, a UPS) are left alone unless --all-ports says otherwise.
  for (const auto& p : drivers::enumerate_serial_ports()) {
    bool known = p.usb_vid && p.usb_pid && !bu::known_usb_device(*p.usb_vid, *p.usb_pid, p.usb_product).empty();
    if (o.all_ports || known) {
      out.push_back({p.path, ""});
    } else {
      skipped.push_back({{"path", p.path}, {"reason", "not a known instrument adapter (probe it with --port or --all-ports)"}});
    }
  }
  return out;
}

// Runs every port's examination at once on one io_context: the slowest port bounds the whole.
std::vector<bu::Examination> examine_all(const std::vector<PortPlan>& plans, bool measure,
                                         std::vector<std::unique_ptr<bu::Recording>>& recordings) {
  boost::asio::io_context io;
  std::vector<bu::Examination> results(plans.size());
  recordings.clear();
  for (std::size_t i = 0; i < plans.size(); ++i) {
    recordings.push_back(std::make_unique<bu::Recording>());
    bu::ExamineOptions eo;
    eo.expect = plans[i].expect;
    eo.measure = measure;
    boost::asio::co_spawn(
        io,
        [&, i, eo]() -> boost::asio::awaitable<void> {
          try {
            results[i] = co_await bu::examine_port(io.get_executor(), plans[i].path, eo, *recordings[i]);
          } catch (const Error& e) {
            results[i].port = plans[i].path;
            results[i].expected_kind = plans[i].expect;
            results[i].verdict = "failed";
            results[i].message = e.info().message;
            results[i].hint = e.hint();
          }
        },
        boost::asio::detached);
  }
  io.run();
  return results;
}

std::string utc_stamp(const char* format) {
  std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, format, &tm);
  return buf;
}

// Questions go to stderr (as `read -p` does), so --json keeps stdout for the report alone.
std::optional<std::string> ask(const std::string& question) {
  std::cerr << question << " " << std::flush;
  std::string line;
  const bool ok = static_cast<bool>(std::getline(std::cin, line));
  if (!::isatty(STDIN_FILENO)) std::cerr << "\n";  // piped answers are not echoed: keep one question a line
  if (!ok) return std::nullopt;
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line;
}

// Half a unit of the last digit the operator typed: "245.5" → 0.05, "12" → 0.5.
double typed_resolution(const std::string& text) {
  auto dot = text.find('.');
  int decimals = dot == std::string::npos ? 0 : static_cast<int>(text.size() - dot - 1);
  return 0.5 * std::pow(10.0, -decimals);
}

// Asks the operator for each value to confirm; returns the expected values and whether any
// disagrees with colorlab's decoding.
json confirm_values(const bu::Examination& x, bool& disagrees, bool& any_confirmed) {
  json expected = json::object();
  for (const auto& c : x.confirmations) {
    const json decoded = x.decoded.value(c.key, json());
    std::string shown = decoded.is_string() ? decoded.get<std::string>() : decoded.dump();
    auto answer = ask("  " + x.port + ": " + c.question + " colorlab decoded " + shown + (c.unit.empty() ? "" : " " + c.unit) +
                      ".\n    Enter if the instrument shows the same, type what it shows, or '-' to leave it unconfirmed:");
    if (!answer || *answer == "-") continue;
    any_confirmed = true;
    if (answer->empty()) {
      expected[c.key] = {{"value", decoded}, {"confirmed", "operator: the instrument shows the decoded value"}};
      continue;
    }
    if (decoded.is_number()) {
      double v = 0;
      try {
        std::size_t used = 0;
        v = std::stod(*answer, &used);
        if (used != answer->size()) throw std::invalid_argument(*answer);
      } catch (const std::exception&) {
        throw Error(ErrorClass::bad_parameter, "'" + *answer + "' is not a number", "type the value as the display shows it, e.g. 245.5");
      }
      double tol = typed_resolution(*answer);
      expected[c.key] = {{"value", v}, {"tolerance", tol}, {"confirmed", "operator typed " + *answer}};
      if (std::abs(v - decoded.get<double>()) > tol) disagrees = true;
    } else {
      expected[c.key] = {{"value", *answer}, {"confirmed", "operator typed " + *answer}};
      if (*answer != shown) disagrees = true;
    }
  }
  return expected;
}

std::string file_stem(const bu::Examination& x) {
  std::string base = fs::path(x.port).filename().string();
  return (x.kind.empty() ? std::string("unknown") : x.kind) + "-" + base;
}

json write_record(const fs::path& dir, const bu::Examination& x, const bu::Recording& rec, const json& expected,
                  const std::string& source, const std::string& phase) {
  bu::TranscriptFile f;
  f.header = {{"port", x.port},
              {"recorded_utc", utc_stamp("%Y-%m-%dT%H:%M:%SZ")},
              {"recorded_by", "colorlab doctor " COLORLAB_DOCTOR_VERSION},
              {"plan", {{"expect", x.expected_kind}, {"measure", phase == "reading"}, {"order", bu::probe_order(x.expected_kind)}}},
              {"verdict", x.verdict},
              {"kind", x.kind}};
  f.events = rec.events();
  f.decoded = x.decoded;
  f.expected = expected;
  f.expected_source = source;
  if (source.empty()) f.expected_note = "unconfirmed: no operator confirmed these values; fill \"expected\" before committing this as a test";
  fs::create_directories(dir);
  auto path = dir / (file_stem(x) + "-" + phase + ".jsonl");
  bu::write_transcript(path, f);
  return path.string();
}

// A relay board's transcript: "transport": "hid" tells the replay to play it as a HID device, and
// "hid" keeps what the transport said of it (the product string sets the relay count).
json write_relay_record(const fs::path& dir, const json& r, const bu::Recording& rec) {
  bu::TranscriptFile f;
  f.header = {{"port", r["where"]},
              {"transport", "hid"},
              {"kind", "hidrelay"},
              {"recorded_utc", utc_stamp("%Y-%m-%dT%H:%M:%SZ")},
              {"recorded_by", "colorlab doctor " COLORLAB_DOCTOR_VERSION},
              {"plan", {{"measure", false}}},
              {"verdict", r["verdict"]},
              {"hid", r.value("hid", json::object())}};
  f.events = rec.events();
  if (r["verdict"] == "identified") f.decoded = {{"board_id", r["board_id"]}, {"relays", r["relays"]}, {"relays_on", r["relays_on"]}};
  f.expected_note = "unconfirmed: fill \"expected\" (e.g. board_id from the board's own listing) before committing this as a test";
  fs::create_directories(dir);
  std::string base = fs::path(r["where"].get<std::string>()).filename().string();
  auto path = dir / ("hidrelay-" + base + "-identify.jsonl");
  bu::write_transcript(path, f);
  return path.string();
}

int run_doctor(const GlobalOptions& g, const DoctorOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  json report = json::object();
  json skipped = json::array();
  auto plans = plan_ports(o, skipped);  // usage errors before any work
  bu::HostPaths paths;
  if (!o.no_host) {
    report["host"] = bu::host_identity();
    report["udev_rules"] = bu::udev_rules_state(paths);
    report["serial_ports"] = bu::serial_ports(paths);
    report["usb_devices"] = bu::usb_devices(paths);
    report["relay_boards"] = bu::relay_boards();
  }
  report["skipped_ports"] = skipped;

  const bool interactive = ::isatty(STDIN_FILENO) && !o.yes;
  bool consent = o.measure || o.yes;
  std::vector<std::unique_ptr<bu::Recording>> recordings;
  auto results = examine_all(plans, consent, recordings);
  std::vector<std::string> phases(results.size(), consent ? "reading" : "identify");

  json cameras = json::array();
  if (!o.no_gige) report["gige_discovered"] = bu::discover_gige_cameras();
  for (const auto& c : o.cameras) cameras.push_back(bu::identify_gige_camera(c));
  json relays = json::array();
  auto relay_paths = o.relays;
  for (const auto& b : drivers::enumerate_relay_boards()) {
    if (std::find(relay_paths.begin(), relay_paths.end(), b.path) == relay_paths.end()) relay_paths.push_back(b.path);
  }
  // Relay boards have no display to confirm and nothing is switched here: their transcripts are
  // recorded unconfirmed (docs/bring-up.md says how to make one a test).
  std::vector<std::unique_ptr<bu::Recording>> relay_recordings;
  for (const auto& r : relay_paths) {
    relay_recordings.push_back(std::make_unique<bu::Recording>());
    relays.push_back(bu::identify_relay(r, relay_recordings.back().get()));
  }

  if (!consent && interactive && !g.json) {
    int n = 0;
    for (const auto& x : results) n += x.verdict == "identified" ? 1 : 0;
    if (n > 0) {
      json first = report;
      first["ports"] = json::array();
      for (const auto& x : results) first["ports"].push_back(bu::to_json(x));
      first["cameras"] = cameras;
      first["relays"] = relays;
      first["interim"] = true;
      std::cout << render_report(first);
      auto a = ask("Take one reading from each of the " + std::to_string(n) +
                   " identified instruments? The SpectroScan moves to its white tile and calibrates, the LS-110 measures; "
                   "no lamp is switched. [y/N]");
      if (a && (*a == "y" || *a == "Y" || *a == "yes")) {
        std::vector<PortPlan> again;
        for (const auto& x : results) {
          if (x.verdict == "identified") again.push_back({x.port, x.kind});
        }
        std::vector<std::unique_ptr<bu::Recording>> more;
        auto measured = examine_all(again, true, more);
        for (std::size_t i = 0; i < measured.size(); ++i) {
          results.push_back(std::move(measured[i]));
          recordings.push_back(std::move(more[i]));
          phases.push_back("reading");
        }
      }
    }
  }

  bool disagreement = false;
  json ports = json::array();
  fs::path dir = o.record.empty() ? fs::path("colorlab-doctor-" + utc_stamp("%Y%m%dT%H%M%SZ")) : fs::path(o.record);
  for (std::size_t i = 0; i < results.size(); ++i) {
    auto& x = results[i];
    json expected = json::object();
    bool disagrees = false, any = false;
    if (x.measured && !o.yes) expected = confirm_values(x, disagrees, any);
    json j = bu::to_json(x);
    j["phase"] = phases[i];
    if (any) j["operator_confirmed"] = expected;
    if (disagrees) {
      j["operator_disagrees"] = true;
      disagreement = true;
    }
    if (!o.no_record) {
      j["transcript"] = write_record(dir, x, *recordings[i], expected, any ? "operator" : "", phases[i]);
    }
    ports.push_back(j);
  }
  report["ports"] = ports;
  if (!o.no_record) {
    for (std::size_t i = 0; i < relays.size(); ++i) relays[i]["transcript"] = write_relay_record(dir, relays[i], *relay_recordings[i]);
  }
  report["cameras"] = cameras;
  report["relays"] = relays;
  bool all_ok = !disagreement;
  for (const auto& x : results) all_ok = all_ok && x.verdict == "identified";
  for (const auto& c : cameras) all_ok = all_ok && c["verdict"] == "identified";
  for (const auto& r : relays) all_ok = all_ok && r["verdict"] == "identified";
  report["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report["ok"] = all_ok;
  const int rc = all_ok ? 0 : 3;
  report["exit_code"] = rc;
  if (std::none_of(results.begin(), results.end(), [](const bu::Examination& x) { return x.measured; })) {
    report["readings"] = "none taken: nothing is measured, moved or lit unasked (run with --measure to take one from each)";
  }
  if (g.json) {
    std::cout << report.dump(2) << "\n";
  } else {
    std::cout << render_report(report);
  }
  return rc;
}

}  // namespace

void add_doctor_command(CLI::App& app, GlobalOptions& global) {
  auto o = std::make_shared<DoctorOptions>();
  auto* cmd = app.add_subcommand("doctor",
                                 "bring-up check of the instruments on this machine, no daemon needed: devices and their udev "
                                 "identities, permissions, udev rules, who answers on each port, calibration state; one "
                                 "reading each only when agreed (docs/bring-up.md)");
  cmd->add_option("--port", o->ports, "a serial port to examine, PATH or PATH=KIND (KIND: dmx, ls110, spectrolino); repeatable")
      ->type_name("PATH[=KIND]");
  cmd->add_flag("--all-ports", o->all_ports, "without --port: examine every serial port, not only known instrument adapters");
  cmd->add_option("--camera", o->cameras, "a GigE Vision camera's address to identify (Aravis); repeatable")->type_name("ADDRESS");
  cmd->add_option("--relay", o->relays,
                  "a relay board to identify: its hidraw path, or unix:PATH for the simulated lab's (boards hidapi finds are "
                  "identified anyway); repeatable")
      ->type_name("WHERE");
  cmd->add_flag("--no-gige", o->no_gige, "skip Aravis's GigE Vision broadcast discovery");
  cmd->add_flag("--no-host", o->no_host, "skip the host listing (devices, permissions, udev rules)");
  cmd->add_flag("--measure", o->measure,
                "agree to one reading from each identified instrument (the SpectroScan moves to its white tile; no lamp is "
                "switched); the values are then confirmed on stdin");
  cmd->add_flag("--yes", o->yes, "agree to the readings and ask nothing (values are recorded unconfirmed)");
  cmd->add_option("--record", o->record, "directory for the transcripts (default: colorlab-doctor-<UTC time>)")->type_name("DIR");
  cmd->add_flag("--no-record", o->no_record, "write no transcript files");
  cmd->callback([&global, o] {
    int rc = run_doctor(global, *o);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace colorlab::cli
