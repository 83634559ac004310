#include "colorlab/campaigns/lab.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <utility>

#include <boost/asio/steady_timer.hpp>
#include <boost/asio/use_awaitable.hpp>

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/campaigns/chart_photograph.hpp"
#include "colorlab/campaigns/lab_calls.hpp"
#include "colorlab/campaigns/floor_photograph.hpp"
#include "colorlab/campaigns/frame_statistics.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/drivers/camera/asio_camera.hpp"
#include "colorlab/drivers/camera/camera_instrument.hpp"
#include "colorlab/drivers/lab_capabilities.hpp"

#include "colorlab/campaigns/roles.hpp"

namespace colorlab::campaigns {

namespace asio = boost::asio;
using nlohmann::json;
using drivers::Capability;
namespace cam = drivers::camera;

namespace {

drivers::SpectralMode mode_from(const std::string& m) {
  if (m == "reflectance") return drivers::SpectralMode::reflectance;
  if (m == "emission") return drivers::SpectralMode::emission;
  if (m == "transmission") return drivers::SpectralMode::transmission;
  throw Error(ErrorClass::script_error, "lab.spectro.mode: '" + m + "' is not reflectance, emission or transmission");
}

json spectrum_json(const drivers::SpectralReading& r, const std::string& instrument) {
  json j{{"mode", std::string(drivers::to_string(r.mode))},
         {"first_nm", r.first_nm},
         {"step_nm", r.step_nm},
         {"values", r.values},
         {"attempts", r.attempts},
         {"instrument", instrument}};
  if (r.xyz) {
    const auto& x = *r.xyz;
    j["XYZ"] = {x[0], x[1], x[2]};
    if (r.mode != drivers::SpectralMode::emission) {
      auto lab = analysis::xyz_to_lab({x[0], x[1], x[2]}, analysis::kIccD50White);
      j["Lab"] = {lab.L, lab.a, lab.b};
    }
  }
  return j;
}

}  // namespace

StabilityCriterion StabilityCriterion::from_json(const json& j, const StabilityCriterion& d) {
  StabilityCriterion c = d;
  if (!j.is_object()) return c;
  auto number = [&](const char* key, double& out, double lo, double hi) {
    if (!j.contains(key)) return;
    if (!j[key].is_number() || !(j[key].get<double>() >= lo && j[key].get<double>() <= hi)) {
      throw Error(ErrorClass::script_error, std::string("lab.wait_stable: ") + key + " must be a number from " +
                                                std::to_string(lo) + " to " + std::to_string(hi));
    }
    out = j[key].get<double>();
  };
  number("tolerance_pct", c.tolerance_pct, 1e-4, 100);
  number("window_s", c.window_s, 0, 86400);
  number("interval_s", c.interval_s, 0.01, 3600);
  number("timeout_s", c.timeout_s, 0, 7 * 86400);
  return c;
}

Lab::Lab(asio::any_io_executor executor, const InstrumentSet& instruments, LabOptions options)
    : executor_(std::move(executor)), instruments_(instruments), options_(options),
      light_(options.suspend.drift_tolerance_pct) {
  if (!(options_.time_scale > 0)) options_.time_scale = 1;
}

template <class T>
std::shared_ptr<T> Lab::find_role(const std::string& name) const {
  auto capability = capability_of(name);
  // One whose port is not there last: another may serve the role; if none does, reaching for the absent
  // one fails no_comms, which suspends a running campaign until it is plugged in again.
  for (bool absent_too : {false, true}) {
    for (const auto& i : instruments_.all()) {
      if (!absent_too && InstrumentSet::port_missing(*i)) continue;
      for (auto c : i->capabilities()) {
        if (c == capability) {
          if (auto t = std::dynamic_pointer_cast<T>(i)) return t;
        }
      }
    }
  }
  return nullptr;
}

template <class T>
std::shared_ptr<T> Lab::role(const std::string& name) const {
  if (auto t = find_role<T>(name)) return t;
  refuse_role(instruments_, name);
}

template <class T>
asio::awaitable<std::shared_ptr<T>> Lab::acquire(const std::string& name) {
  if (auto t = find_role<T>(name)) {
    co_await ready(*t);
    co_return t;
  }
  // A driver may learn what it offers only when connected (a Spectrolino is on a table or not):
  // connect the candidates, then look again.
  for (const auto& i : instruments_.all()) {
    auto s = i->state();
    if (!std::dynamic_pointer_cast<T>(i) ||
        (s != drivers::InstrumentState::disconnected && s != drivers::InstrumentState::initialising)) {
      continue;
    }
    try {
      co_await ready(*i);
    } catch (const Error&) {
      continue;
    }
  }
  co_return role<T>(name);
}

template <class T>
bool Lab::may_offer(const std::string& name) const {
  // One whose device path is not there cannot serve before someone plugs it in: refused now, with why.
  const auto capability = capability_of(name);
  for (const auto& i : instruments_.all()) {
    if (!std::dynamic_pointer_cast<T>(i) || InstrumentSet::port_missing(*i)) continue;
    auto caps = i->capabilities();
    if (std::find(caps.begin(), caps.end(), capability) != caps.end()) return true;
    auto s = i->state();
    if (s == drivers::InstrumentState::disconnected || s == drivers::InstrumentState::initialising) return true;
  }
  return false;
}

void Lab::check_needs(const std::vector<std::string>& roles) const {
  // An instrument still connecting may turn out to offer the role: accept it now, decide at the call.
  for (const auto& r : roles) {
    bool ok = r == "luminance_meter"     ? may_offer<drivers::LuminanceMeter>(r)
              : r == "spectrophotometer" ? may_offer<drivers::Spectrometer>(r)
              : r == "table"             ? may_offer<drivers::XyTable>(r)
              : r == "lamps"             ? may_offer<drivers::LampController>(r)
              : r == "dimmer"            ? may_offer<drivers::Dimmer>(r)
                                         : may_offer<cam::CameraInstrument>(r);
    if (!ok) refuse_role(instruments_, r);
  }
}

asio::awaitable<std::vector<std::string>> Lab::serial_mismatches(std::map<std::string, std::string> expected) {
  std::vector<std::string> out;
  for (const auto& [id, serial] : expected) {
    auto i = instruments_.find(id);
    if (!i || serial.empty()) continue;
    log::debug("lab", "checking " + id + " is still the unit the run started with");
    try {
      co_await ready(*i);
    } catch (const Error&) {
      continue;  // not there at all: the lab call that needs it reports that
    }
    auto now = i->identity().serial;
    if (!now.empty() && now != serial) out.push_back(id + ": the run started with serial " + serial + ", now " + now);
  }
  co_return out;
}

asio::awaitable<void> Lab::ready(drivers::Instrument& instrument) {
  using drivers::InstrumentState;
  auto deadline = std::chrono::steady_clock::now() + options_.connect_timeout;
  for (;;) {
    auto s = instrument.state();
    if (drivers::needs_connect(s)) {
      co_await instrument.connect();
      co_return;
    }
    if (s != InstrumentState::initialising) co_return;
    // Connecting at daemon start (discovery got there first): wait for it rather than interleave.
    if (std::chrono::steady_clock::now() > deadline) {
      throw Error(ErrorClass::timeout, instrument.id() + " is still connecting after " +
                                           std::to_string(options_.connect_timeout.count()) + " s");
    }
    asio::steady_timer t(executor_, std::chrono::milliseconds(20));
    co_await t.async_wait(asio::use_awaitable);
  }
}

asio::awaitable<void> Lab::sleep_lab_seconds(double seconds, const ExecutionControl& control) {
  auto end = std::chrono::steady_clock::now() +
             std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds / options_.time_scale));
  for (;;) {
    if (control.requested()) throw Error(ErrorClass::aborted, "wait interrupted: " + control.reason);
    auto now = std::chrono::steady_clock::now();
    if (now >= end) co_return;
    asio::steady_timer t(executor_, std::min<std::chrono::steady_clock::duration>(end - now, std::chrono::milliseconds(100)));
    co_await t.async_wait(asio::use_awaitable);
  }
}

asio::awaitable<json> Lab::wait_stable(const StabilityCriterion& c, const ExecutionControl& control) {
  auto meter = co_await acquire<drivers::LuminanceMeter>("luminance_meter");
  auto start = std::chrono::steady_clock::now();
  auto lab_seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() * options_.time_scale;
  };
  std::deque<std::pair<double, double>> window;  // (lab time, luminance)
  int readings = 0;
  double drift_pct = 100;
  for (;;) {
    if (control.requested()) throw Error(ErrorClass::aborted, "wait_stable interrupted: " + control.reason);
    auto r = co_await meter->measure_luminance();
    ++readings;
    double t = lab_seconds();
    log::debug("lab", "wait_stable: reading " + std::to_string(readings) + " at " + std::to_string(t) + " s: " +
                          std::to_string(r.luminance) + " " + r.unit);
    window.emplace_back(t, r.luminance);
    // Keep the shortest tail of readings that still spans the whole window.
    while (window.size() > 3 && t - window[1].first >= c.window_s) window.pop_front();
    if (window.size() >= 3 && t - window.front().first >= c.window_s) {
      // Drift from a straight-line fit, not max − min: the meter's noise must not read as drift.
      double n = static_cast<double>(window.size()), st = 0, sl = 0, stt = 0, stl = 0;
      for (auto [ti, li] : window) {
        st += ti;
        sl += li;
        stt += ti * ti;
        stl += ti * li;
      }
      double denom = n * stt - st * st;
      double slope = denom > 0 ? (n * stl - st * sl) / denom : 0;
      double mean = sl / n;
      drift_pct = mean > 0 ? std::abs(slope) * c.window_s / mean * 100 : 100;
      log::debug("lab", "wait_stable: " + std::to_string(r.luminance) + " " + r.unit + ", drift " +
                            std::to_string(drift_pct) + " % over " + std::to_string(c.window_s) + " s");
      if (drift_pct <= c.tolerance_pct) {
        co_return json{
            {"luminance", r.luminance},
            {"unit", r.unit},
            {"instrument", meter->id()},
            {"drift_pct", drift_pct},
            {"readings", readings},
            {"waited_s", t},
        };
      }
    }
    if (t >= c.timeout_s) {
      ErrorInfo info;
      info.cls = ErrorClass::needs_operator;
      info.message = "the light did not settle within " + std::to_string(static_cast<int>(c.timeout_s)) + " s (drift " +
                     std::to_string(drift_pct) + " % over " + std::to_string(static_cast<int>(c.window_s)) + " s)";
      info.hint = "check the lamp; a failing tube flickers and drifts";
      info.device_code = "lamp:unstable";
      throw Error(std::move(info));
    }
    co_await sleep_lab_seconds(c.interval_s, control);
  }
}

asio::awaitable<void> Lab::switch_lamps(std::vector<std::string> on) {
  auto lamps = co_await acquire<drivers::LampController>("lamps");
  auto before = lamps->lamps_on();
  co_await lamps->set_lamps(on);
  if (before != on) {
    stable_light_.reset();
    light_.forget();
  }
  for (const auto& l : on) {
    if (std::find(before.begin(), before.end(), l) == before.end()) known_warm_.erase(l);
  }
  for (const auto& l : before) {
    if (std::find(on.begin(), on.end(), l) == on.end()) known_warm_.erase(l);
  }
}

void Lab::follow_execution(const ExecutionControl& control) {
  if (control.execution_id == light_execution_) return;
  // Another execution: the meter may have been aimed anew in between, and no suspension of its own is pending.
  light_execution_ = control.execution_id;
  light_.forget();
  resumed_note_.reset();
}

asio::awaitable<json> Lab::perform(const std::string& call, const json& args, const ExecutionControl& control) {
  follow_execution(control);
  // What an attempt of this execution that failed kept is no call's; another execution's call may be mid-way.
  if (auto it = ledgers_.find(control.execution_id); it != ledgers_.end()) it->second.take();
  const LabCall* c = find_lab_call(call);
  if (!c || !c->perform) throw Error(ErrorClass::internal, "the lab has no call " + call);
  json result = co_await (this->*(c->perform))(args, control);
  co_return result;
}

FrameKeeper* Lab::call_keeper(const ExecutionControl& control) {
  if (!keeper_) return nullptr;
  auto [it, made] = ledgers_.try_emplace(control.execution_id);
  if (made) it->second.set_keeper(keeper_);
  return &it->second;
}

void Lab::set_frame_keeper(FrameKeeper* keeper) {
  keeper_ = keeper;
  for (auto& [execution, ledger] : ledgers_) ledger.set_keeper(keeper);
}

std::vector<KeptBlob> Lab::take_kept(const std::string& execution_id) {
  auto it = ledgers_.find(execution_id);
  return it == ledgers_.end() ? std::vector<KeptBlob>{} : it->second.take();
}

asio::awaitable<std::shared_ptr<cam::CameraInstrument>> Lab::camera_named_in(const json& options) {
  // A lab with two cameras (GenICam and DSLR) lets the script say which one: {camera = id or kind}.
  if (options.is_object() && options.contains("camera")) {
    auto camera = select_camera(instruments_, options["camera"]);
    co_await ready(*camera);
    co_return camera;
  }
  co_return co_await acquire<cam::CameraInstrument>("camera");
}

asio::awaitable<json> Lab::call_meter_measure(const json&, const ExecutionControl&) {
  auto meter = co_await acquire<drivers::LuminanceMeter>("luminance_meter");
  auto r = co_await meter->measure_luminance();
  check_dropout(r.luminance, r.unit);
  check_drift(r.luminance, r.unit);
  json result{{"luminance", r.luminance}, {"unit", r.unit}, {"instrument", meter->id()}, {"raw", r.raw_reply}};
  if (resumed_note_) result["resumed_after"] = *std::exchange(resumed_note_, std::nullopt);
  co_return result;
}

asio::awaitable<json> Lab::call_wait_stable(const json& args, const ExecutionControl& control) {
  auto c = StabilityCriterion::from_json(args.empty() ? json::object() : args[0], options_.warmup);
  json r = co_await wait_stable(c, control);
  note_stable(r["luminance"].get<double>());
  if (auto lamps = find_role<drivers::LampController>("lamps")) {
    for (const auto& l : lamps->lamps_on()) known_warm_.insert(l);
  }
  if (resumed_note_) r["resumed_after"] = *std::exchange(resumed_note_, std::nullopt);
  co_return r;
}

asio::awaitable<json> Lab::call_lamps_select(const json& args, const ExecutionControl&) {
  std::vector<std::string> on{args[0].get<std::string>()};
  co_await switch_lamps(on);
  json result = json::object();
  result["lamps_on"] = on;
  co_return result;
}

asio::awaitable<json> Lab::call_lamps_set(const json& args, const ExecutionControl&) {
  std::vector<std::string> on;
  for (const auto& l : args[0]) {
    if (!l.is_string()) throw Error(ErrorClass::script_error, "lab.lamps.set takes a list of lamp names");
    on.push_back(l.get<std::string>());
  }
  co_await switch_lamps(on);
  co_return json{{"lamps_on", on}};
}

asio::awaitable<json> Lab::call_lamps_off(const json&, const ExecutionControl&) {
  std::vector<std::string> none;
  co_await switch_lamps(none);
  json result = json::object();
  result["lamps_on"] = json::array();
  co_return result;
}

asio::awaitable<json> Lab::call_lamps_names(const json&, const ExecutionControl&) {
  auto lamps = role<drivers::LampController>("lamps");
  co_return json(lamps->lamp_names());
}

asio::awaitable<json> Lab::call_dimmer_set(const json& args, const ExecutionControl& control) {
  auto dimmer = co_await acquire<drivers::Dimmer>("dimmer");
  const std::string channel = "dimmer";
  co_await dimmer->set_level(channel, args[0].get<double>() / 100.0);
  dimmer_percent_ = args[0].get<double>();
  // The driver ramps at its configured rate and settles; a script may ask for more settling.
  if (args.size() > 1 && args[1].is_object() && args[1].contains("settle_s")) {
    double settle = args[1]["settle_s"].is_number() ? args[1]["settle_s"].get<double>() : -1;
    if (!(settle >= 0 && settle <= 3600)) throw Error(ErrorClass::script_error, "lab.dimmer.set: settle_s must be from 0 to 3600");
    co_await sleep_lab_seconds(settle, control);
  }
  co_return json{{"dimmer_percent", args[0]}};
}

asio::awaitable<json> Lab::call_table_move(const json& args, const ExecutionControl&) {
  auto table = co_await acquire<drivers::XyTable>("table");
  co_await table->move_to(args[0].get<double>(), args[1].get<double>());
  co_return json(nullptr);
}

asio::awaitable<json> Lab::call_table_home(const json&, const ExecutionControl&) {
  auto table = co_await acquire<drivers::XyTable>("table");
  co_await table->home();
  co_return json(nullptr);
}

asio::awaitable<json> Lab::call_table_head_up(const json&, const ExecutionControl&) {
  auto table = co_await acquire<drivers::XyTable>("table");
  co_await table->head_up();
  co_return json(nullptr);
}

asio::awaitable<json> Lab::call_table_head_down(const json&, const ExecutionControl&) {
  auto table = co_await acquire<drivers::XyTable>("table");
  co_await table->head_down();
  co_return json(nullptr);
}

asio::awaitable<json> Lab::call_table_hold_paper(const json& args, const ExecutionControl&) {
  auto table = co_await acquire<drivers::XyTable>("table");
  co_await table->hold_paper(args[0].get<bool>());
  co_return json(nullptr);
}

asio::awaitable<json> Lab::call_table_measure_at(const json& args, const ExecutionControl&) {
  auto table = co_await acquire<drivers::XyTable>("table");
  auto r = co_await table->move_and_measure(args[0].get<double>(), args[1].get<double>());
  co_return spectrum_json(r, table->id());
}

asio::awaitable<json> Lab::call_table_read_patch(const json& args, const ExecutionControl&) {
  auto table = co_await acquire<drivers::XyTable>("table");
  drivers::ChartPatchVisit visit;
  visit.x_mm = args[0].get<double>();
  visit.y_mm = args[1].get<double>();
  const json options = args.size() > 2 && args[2].is_object() ? args[2] : json::object();
  visit.row_start = options.value("row_start", false);
  visit.row_length = options.value("row_length", 1);
  visit.index = options.value("index", 0);
  if (visit.row_length < 1 || visit.row_length > 1000) {
    throw Error(ErrorClass::script_error, "lab.table.read_patch: row_length must be from 1 to 1000");
  }
  auto r = co_await table->read_chart_patch(visit);
  json j = spectrum_json(r, table->id());
  // How long the white calibration lasts from here: shows where the table recalibrated.
  for (const auto& c : table->calibration()) {
    if (c.valid && c.readings_left) j["calibration_readings_left"] = *c.readings_left;
  }
  co_return j;
}

asio::awaitable<json> Lab::call_spectro_mode(const json& args, const ExecutionControl&) {
  auto spectro = co_await acquire<drivers::Spectrometer>("spectrophotometer");
  co_await spectro->set_mode(mode_from(args[0].get<std::string>()));
  co_return json(nullptr);
}

asio::awaitable<json> Lab::call_spectro_calibrate(const json&, const ExecutionControl&) {
  auto spectro = co_await acquire<drivers::Spectrometer>("spectrophotometer");
  co_await spectro->calibrate();
  co_return json(nullptr);
}

asio::awaitable<json> Lab::call_spectro_measure(const json&, const ExecutionControl&) {
  auto spectro = co_await acquire<drivers::Spectrometer>("spectrophotometer");
  auto r = co_await spectro->measure();
  co_return spectrum_json(r, spectro->id());
}

asio::awaitable<json> Lab::call_camera_configure(const json& args, const ExecutionControl&) {
  // configure{camera = id or kind} sets the one a later photograph_chart names on a lab with two.
  auto camera = co_await camera_named_in(args[0]);
  cam::CameraSettings s;
  for (const auto& [key, value] : args[0].items()) {
    if (key == "camera") continue;
    if (!value.is_number()) throw Error(ErrorClass::script_error, "lab.camera.configure: " + key + " must be a number");
    if (key == "iso") s.iso = value.get<int>();
    else if (key == "shutter_s") s.shutter_s = value.get<double>();
    else if (key == "aperture_f") s.aperture_f = value.get<double>();
    else if (key == "exposure_us") s.exposure_us = value.get<double>();
    else if (key == "gain") s.gain = value.get<double>();
    else throw Error(ErrorClass::script_error, "lab.camera.configure: unknown setting '" + key + "' (iso, shutter_s, aperture_f, exposure_us, gain, camera)");
  }
  auto error = co_await cam::async_configure(camera->camera(), s, asio::use_awaitable);
  if (error) throw *error;
  co_return json(nullptr);
}

asio::awaitable<json> Lab::call_camera_capture(const json& args, const ExecutionControl& control) {
  auto camera = co_await acquire<cam::CameraInstrument>("camera");
  // Named, not a temporary in the co_await: GCC 12 destroys such temporaries twice.
  json options = args.empty() ? json::object() : args[0];
  json table = co_await capture_noise_table(*camera, options, call_keeper(control));
  co_return table;
}

asio::awaitable<json> Lab::call_camera_photograph_chart(const json& args, const ExecutionControl& control) {
  json options = args.empty() ? json::object() : args[0];
  auto camera = co_await camera_named_in(options);
  json photographs = co_await photograph_chart(*camera, options, call_keeper(control));
  co_return photographs;
}

asio::awaitable<json> Lab::call_camera_photograph_floor(const json& args, const ExecutionControl& control) {
  auto camera = co_await acquire<cam::CameraInstrument>("camera");
  json options = args[0];
  json photograph = co_await photograph_floor(*camera, options, call_keeper(control));
  co_return photograph;
}

asio::awaitable<json> Lab::call_runs_chart_reference(const json& args, const ExecutionControl&) {
  if (!runs_) throw Error(ErrorClass::unsupported, "lab.runs.chart_reference: this lab keeps no runs to read");
  co_return chart_reference(*runs_, args[0].get<std::string>());
}

asio::awaitable<json> Lab::call_operator_request(const json& args, const ExecutionControl& control) {
  json answer = co_await operator_request(args[0], control);
  // Whoever answered may have moved the meter (aiming it is what most requests are about): readings
  // from here on are not comparable with those before.
  light_.moved();
  aimed_since_stable_ = true;
  co_return answer;
}

asio::awaitable<json> Lab::call_wait(const json& args, const ExecutionControl& control) {
  co_await sleep_lab_seconds(args[0].get<double>(), control);
  co_return json(nullptr);
}

asio::awaitable<json> Lab::call_now(const json&, const ExecutionControl&) {
  auto now = std::chrono::system_clock::now();
  co_return json{{"utc", now_iso8601()}, {"unix", std::chrono::duration<double>(now.time_since_epoch()).count()}};
}

asio::awaitable<json> Lab::restore(const LabState& desired, const ExecutionControl& control) {
  follow_execution(control);
  json done = json::array();
  std::shared_ptr<drivers::XyTable> table;
  if (desired.table_used) {
    table = co_await acquire<drivers::XyTable>("table");
    // A process killed mid-move may have left the head down: never drag it across the chart.
    co_await table->head_up();
    done.push_back("head up");
  }
  if (desired.spectro_mode || desired.spectro_calibrated) {
    auto spectro = co_await acquire<drivers::Spectrometer>("spectrophotometer");
    if (desired.spectro_mode) co_await spectro->set_mode(mode_from(*desired.spectro_mode));
    if (desired.spectro_calibrated) {
      bool valid = false;
      for (const auto& c : spectro->calibration()) valid = valid || c.valid;
      // The calibration lived in the previous process's driver (and the instrument may have been
      // power-cycled): calibrate again rather than trust it.
      if (!valid) {
        co_await spectro->calibrate();
        done.push_back("white calibration");
      }
    }
  }
  if (desired.lamps_on) {
    // A fresh driver does not know what the widget last sent: send the whole state again.
    co_await switch_lamps(*desired.lamps_on);
    done.push_back(json{{"lamps_on", *desired.lamps_on}});
  }
  if (desired.dimmer_percent) {
    auto dimmer = co_await acquire<drivers::Dimmer>("dimmer");
    const std::string channel = "dimmer";
    co_await dimmer->set_level(channel, *desired.dimmer_percent / 100.0);
    dimmer_percent_ = *desired.dimmer_percent;
    done.push_back(json{{"dimmer_percent", *desired.dimmer_percent}});
  }
  if (desired.any_lamp_on()) {
    log::debug("lab", "restore: waiting for the lamps to be stable again");
    bool warm = std::all_of(desired.lamps_on->begin(), desired.lamps_on->end(),
                            [&](const std::string& l) { return known_warm_.count(l) > 0; });
    if (!warm) {
      if (find_role<drivers::LuminanceMeter>("luminance_meter")) {
        json r = co_await wait_stable(options_.warmup, control);
        note_stable(r["luminance"].get<double>());
        done.push_back(json{{"lamps_stable", r}});
      } else {
        co_await sleep_lab_seconds(options_.lamp_warmup_s, control);
        done.push_back(json{{"lamp_warmup_s", options_.lamp_warmup_s}});
      }
      for (const auto& l : *desired.lamps_on) known_warm_.insert(l);
    }
  }
  if (table) {
    if (desired.table_xy) {
      co_await table->move_to(desired.table_xy->first, desired.table_xy->second);
      done.push_back(json{{"table_mm", {desired.table_xy->first, desired.table_xy->second}}});
    }
    if (desired.head_down) co_await table->head_down();
    if (desired.paper_held) co_await table->hold_paper(*desired.paper_held);
  }
  if (hands_) {
    // What the simulated lab's "hands" did (the meter's aim) died with the old simulator.
    for (const auto& [action, details] : desired.done_by_hands) {
      auto redone = co_await hands_->perform(action, details);
      if (redone) {
        done.push_back(json{{"operator_action", action}, {"details", details}});
        light_.moved();  // the meter was aimed again after the lamps were found stable
        aimed_since_stable_ = true;
      }
    }
  }
  if (!desired.camera_settings.is_null()) {
    const std::string configure = "camera.configure";
    json args = json::array();
    args.push_back(desired.camera_settings);
    co_await perform(configure, args, control);
    done.push_back(json{{"camera", desired.camera_settings}});
  }
  co_return done;
}

asio::awaitable<json> Lab::put_back(const LabState& state) {
  json done = json::array();
  if (!hands_) co_return done;
  for (const auto& [action, details] : state.done_by_hands) {
    try {
      if (auto undone = co_await hands_->put_back(action, details)) {
        log::info("lab", "put back after the run: " + action + " " + undone->dump());
        done.push_back(json{{"operator_action", action}, {"put_back", *undone}});
      }
    } catch (const std::exception& e) {  // a run's outcome is its own: what the hands could not undo is only said
      log::warning("lab", "cannot put back what " + action + " moved: " + e.what());
    }
  }
  co_return done;
}

asio::awaitable<void> Lab::safe_state() {
  for (const auto& i : instruments_.all()) {
    if (i->state() == drivers::InstrumentState::disconnected) continue;
    try {
      if (auto table = std::dynamic_pointer_cast<drivers::XyTable>(i)) {
        co_await table->head_up();
        co_await table->home();
      }
      if (options_.lamps_off_at_shutdown) {
        if (auto lamps = std::dynamic_pointer_cast<drivers::LampController>(i)) {
          std::vector<std::string> none;
          co_await lamps->set_lamps(none);
        }
      }
    } catch (const Error& e) {
      log::warning("lab", i->id() + ": cannot reach the safe state: " + e.what());
    }
  }
}

}  // namespace colorlab::campaigns
