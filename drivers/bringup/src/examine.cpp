#include "colorlab/bringup/examine.hpp"

#include <cstdio>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/enttec_dmx.hpp"
#include "colorlab/drivers/ls110.hpp"
#include "colorlab/drivers/spectrolino.hpp"
#include "colorlab/drivers/spectrolino_link.hpp"

namespace colorlab::bringup {

namespace asio = boost::asio;
namespace sl = colorlab::wire::spectrolino;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

std::chrono::milliseconds scaled(std::chrono::milliseconds d, double scale) {
  return std::chrono::milliseconds(static_cast<long long>(static_cast<double>(d.count()) * std::max(scale, 1.0)));
}

std::string hex_serial(std::uint32_t bcd) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%08X", bcd);
  return buf;
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
  return s;
}

// ---------------------------------------------------------------- per kind

asio::awaitable<void> identify_dmx(asio::any_io_executor ex, Examination& x, const ExamineOptions& o, Recording& rec) {
  drivers::EnttecDmxOptions d;
  d.port = x.port;
  d.attempts = 1;
  d.reply_timeout = scaled(1000ms, o.deadline_scale);
  drivers::EnttecDmx widget(ex, d);
  rec.attach(widget.transcript());
  rec.mark("identify: label 10 serial number, label 3 parameters");
  try {
    co_await widget.connect();  // reads only: no DMX frame is sent on a first connect
  } catch (...) {
    Recording::detach(widget.transcript());
    throw;
  }
  Recording::detach(widget.transcript());
  auto id = widget.identity();
  x.identity = {{"model", id.model}, {"serial", id.serial}, {"firmware", id.firmware}};
  x.decoded["serial"] = hex_serial(widget.widget_serial());
  x.decoded["firmware"] = id.firmware;
  x.calibration = {{"applies", false}, {"detail", "a DMX widget has no calibration"}};
  if (o.measure) {
    // A widget measures nothing and doctor switches no lamp: its reading is who it says it is.
    x.measured = true;
    x.confirmations.push_back({"serial", "Which serial number is printed on the widget's label?", ""});
  }
  widget.disconnect();
}

asio::awaitable<void> identify_ls110(asio::any_io_executor ex, Examination& x, const ExamineOptions& o, Recording& rec) {
  x.identity = {{"model", "Konica Minolta LS-110"},
                {"detail", "the meter has no identification command; it answered MDS,04 in remote mode"}};
  x.calibration = {
      {"applies", true},
      {"state", "factory"},
      {"detail", "the LS-110 reports no calibration over RS-232: its accuracy is Konica Minolta's "
                 "calibration (see the certificate's date); the calibration factor shown on its display applies"},
  };
  if (!o.measure) co_return;
  drivers::Ls110Options d;
  d.port = x.port;
  d.attempts = 1;
  d.reply_timeout = scaled(5000ms, o.deadline_scale);  // PsychoPy's allowance for a reading
  drivers::Ls110 meter(ex, d);
  rec.attach(meter.transcript());
  rec.mark("reading: MDS,04 then MES");
  try {
    co_await meter.connect();
    auto r = co_await meter.measure_luminance();
    x.decoded["luminance"] = r.luminance;
    x.decoded["unit"] = r.unit;
    x.identity["raw_reply"] = r.raw_reply;
  } catch (...) {
    Recording::detach(meter.transcript());
    throw;
  }
  Recording::detach(meter.transcript());
  meter.disconnect();
  x.measured = true;
  x.confirmations.push_back({"luminance", "What luminance does the LS-110's display show?", "cd/m2"});
}

// Read-only queries at the speed the handshake found: the table's type, serial and firmware, or a
// stand-alone Spectrolino's device data and target id. Nothing that homes, moves or changes speed.
asio::awaitable<void> identify_spectrolino_readonly(asio::any_io_executor ex, Examination& x, const Heard& heard,
                                                    const ExamineOptions& o, Recording& rec) {
  drivers::SerialLink link(ex, x.port);
  rec.attach(link.transcript());
  struct Detach {
    drivers::SerialLink& l;
    ~Detach() { Recording::detach(l.transcript()); }
  } detach{link};
  drivers::SpectrolinoTimeouts t;
  t.command = scaled(2000ms, o.deadline_scale);
  drivers::SpectrolinoLink protocol(link, t, 1);
  link.open(drivers::spectrolino_serial_settings(heard.baud, drivers::FlowControl::none));
  const bool table = heard.detail.find("SpectroScan") != std::string::npos;
  try {
    if (table) {
      rec.mark("identify: SpectroScan type, serial, firmware, status");
      auto type = sl::TypeAnswer::decode(co_await protocol.transact(sl::req::output_type(), t.command, "table type"));
      auto ser = sl::SerialNumberAnswer::decode(co_await protocol.transact(sl::req::output_serial(), t.command, "table serial"));
      auto fw = sl::SoftwareVersionAnswer::decode(co_await protocol.transact(sl::req::output_firmware(), t.command, "table firmware"));
      auto st = sl::StatusAnswer::decode(co_await protocol.transact(sl::req::output_status(), t.command, "table status"));
      x.identity = {{"model", trim(type.name) == "SpectroScanT" ? "SpectroScan T (with its Spectrolino)" : "SpectroScan (with its Spectrolino)"},
                    {"table_serial", std::to_string(ser.serial)},
                    {"table_firmware", trim(fw.version)},
                    {"online", (st.bits & 0x10) != 0},
                    {"paper_held", (st.bits & 0x80) != 0},
                    {"baud", heard.baud}};
      x.decoded["table_serial"] = std::to_string(ser.serial);
      x.decoded["topology"] = trim(type.name) == "SpectroScanT" ? "spectroscan_t" : "spectroscan";
    } else {
      rec.mark("identify: Spectrolino device data, target id");
      auto dev = sl::DeviceDataAnswer::decode(co_await protocol.transact(sl::req::device_data_request(), t.command, "device data"));
      auto tid = sl::TargetIdAnswer::decode(co_await protocol.transact(sl::req::target_id_request(), t.command, "target id"));
      x.identity = {
          {"model", trim(tid.name)},
          {"serial", std::to_string(dev.serial)},
          {"firmware", trim(dev.software)},
          {"baud", heard.baud},
      };
      x.decoded["serial"] = std::to_string(dev.serial);
      x.decoded["topology"] = "standalone";
    }
  } catch (const Error& e) {
    protocol.rethrow(e);
  }
  link.close();
}

asio::awaitable<void> identify_spectrolino(asio::any_io_executor ex, Examination& x, const Heard& heard, const ExamineOptions& o,
                                           Recording& rec) {
  co_await identify_spectrolino_readonly(ex, x, heard, o, rec);
  x.calibration = {
      {"applies", true},
      {"state", "unknown"},
      {"detail", "the Spectrolino keeps no white calibration colorlab can read back: the daemon calibrates on "
                 "the white tile before its readings, and doctor --measure does it once"},
  };
  if (!o.measure) co_return;
  drivers::SpectrolinoOptions d;
  d.port = x.port;
  d.initialise_table = false;  // homing is a campaign's decision, not doctor's
  d.command_attempts = 1;
  d.timeouts.probe = scaled(d.timeouts.probe, o.deadline_scale);
  d.timeouts.command = scaled(d.timeouts.command, o.deadline_scale);
  d.reconnect.max_attempts = 0;
  drivers::Spectrolino spectro(ex, d);
  rec.attach(spectro.transcript());
  rec.mark("reading: connect, white calibration on the tile, one measurement there");
  try {
    co_await spectro.connect();
    co_await spectro.calibrate();
    auto r = co_await spectro.measure();
    auto id = spectro.identity();
    x.identity["model"] = id.model;
    x.identity["serial"] = id.serial;
    x.identity["firmware"] = id.firmware;
    x.decoded["serial"] = id.serial.substr(0, id.serial.find('/'));
    x.decoded["spectrum"] = r.values;
    x.decoded["first_nm"] = r.first_nm;
    x.decoded["step_nm"] = r.step_nm;
    if (r.xyz) x.decoded["xyz"] = *r.xyz;
    auto cal = spectro.calibration();
    if (!cal.empty()) {
      x.calibration = {
          {"applies", true},
          {"state", cal.front().valid ? "valid" : "expired"},
          {"type", cal.front().type},
          {"detail", "white calibration made by doctor on the tile just now"},
      };
      if (cal.front().readings_left) x.calibration["readings_left"] = *cal.front().readings_left;
    }
  } catch (...) {
    Recording::detach(spectro.transcript());
    spectro.disconnect();
    throw;
  }
  Recording::detach(spectro.transcript());
  spectro.disconnect();
  x.measured = true;
  x.confirmations.push_back({"serial", "Which serial number is printed on the Spectrolino's label?", ""});
}

std::string list(const std::vector<std::string>& tried) {
  std::string s;
  for (const auto& t : tried) s += (s.empty() ? "" : ", ") + t;
  return s;
}

std::string show_bytes(const std::string& b) {
  auto shown = b.substr(0, 24);
  std::string out;
  for (unsigned char c : shown) {
    char buf[4];
    std::snprintf(buf, sizeof buf, "%02X ", c);
    out += buf;
  }
  if (!out.empty()) out.pop_back();
  if (b.size() > shown.size()) out += " …";
  return out;
}

}  // namespace

std::vector<std::string> probe_order(const std::string& expect) {
  std::vector<std::string> order;
  if (!expect.empty()) {
    instrument_name(expect);  // refuses an unknown kind
    order.push_back(expect);
  }
  for (const auto& k : serial_kinds()) {
    if (k != expect) order.push_back(k);
  }
  return order;
}

asio::awaitable<Examination> examine_port(asio::any_io_executor executor, std::string port, ExamineOptions options,
                                          Recording& recording) {
  const auto start = std::chrono::steady_clock::now();
  Examination x;
  x.port = port;
  x.expected_kind = options.expect;
  HandshakeOptions ho;
  ho.order = probe_order(options.expect);
  ho.deadline_scale = options.deadline_scale;
  auto hs = co_await handshake(executor, port, ho, recording);
  x.tried = hs.tried;
  x.kind = hs.heard.kind;
  const double budget_s = std::chrono::duration<double>(handshake_budget(ho)).count();
  char budget[32];
  std::snprintf(budget, sizeof budget, "%.1f s", budget_s);
  if (!hs.open_error.empty()) {
    x.verdict = "cannot_open";
    x.message = hs.open_error;
    x.hint = hs.open_hint;
  } else if (x.kind.empty() && hs.garbage.empty()) {
    x.verdict = "silent";
    x.message = "nothing answered: no reply to any handshake (" + list(hs.tried) + ") within " + budget;
    x.hint = "check power and cable; an LS-110 answers only in remote mode (switch it on holding F until '[' shows); "
             "a SpectroScan must be online with its Spectrolino docked";
  } else if (x.kind.empty()) {
    x.verdict = "unknown_protocol";
    x.message = "answers, but in no protocol colorlab knows: " + std::to_string(hs.garbage.size()) + " bytes (" +
                show_bytes(hs.garbage) + ") to " + list(hs.tried);
    x.hint = "a different device, a wrong speed or framing on an adapter, or line noise: check which instrument is on "
             "this port and its cable (null-modem for the LS-110 and the Spectrolino)";
  } else if (!options.expect.empty() && x.kind != options.expect) {
    x.verdict = "wrong_instrument";
    x.message = "answers in " + instrument_name(x.kind) + "'s protocol (" + hs.heard.detail + "), not in " +
                instrument_name(options.expect) + "'s this port was given for";
    x.hint = "another instrument is on this port: swap the cables or correct the port in the configuration";
  } else {
    x.verdict = "identified";
    x.message = instrument_name(x.kind) + " answered its own handshake: " + hs.heard.detail +
                (hs.heard.baud ? " at " + std::to_string(hs.heard.baud) + " baud" : "");
  }
  x.decoded["verdict"] = x.verdict;
  if (!x.kind.empty()) x.decoded["kind"] = x.kind;
  if (!x.kind.empty()) {
    // Identify what answered even when it is the wrong one, so the operator learns what it is; a
    // reading only from the instrument the operator expects.
    ExamineOptions io = options;
    io.measure = options.measure && x.verdict == "identified";
    try {
      if (x.kind == "dmx") co_await identify_dmx(executor, x, io, recording);
      if (x.kind == "ls110") co_await identify_ls110(executor, x, io, recording);
      if (x.kind == "spectrolino") co_await identify_spectrolino(executor, x, hs.heard, io, recording);
    } catch (const Error& e) {
      x.verdict = "failed";
      x.decoded["verdict"] = x.verdict;
      x.message = instrument_name(x.kind) + " answered the handshake, then failed: " + e.info().message;
      x.hint = e.hint();
    }
  }
  x.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  co_return x;
}

json to_json(const Examination& e) {
  json confirm = json::array();
  for (const auto& c : e.confirmations) confirm.push_back({{"key", c.key}, {"question", c.question}, {"unit", c.unit}});
  json j{
      {"port", e.port},
      {"verdict", e.verdict},
      {"message", e.message},
      {"tried", e.tried},
      {"identity", e.identity},
      {"calibration", e.calibration},
      {"decoded", e.decoded},
      {"measured", e.measured},
      {"confirm", confirm},
      {"seconds", e.seconds},
  };
  j["kind"] = e.kind.empty() ? json(nullptr) : json(e.kind);
  j["expected_kind"] = e.expected_kind.empty() ? json(nullptr) : json(e.expected_kind);
  if (!e.hint.empty()) j["hint"] = e.hint;
  return j;
}

}  // namespace colorlab::bringup
