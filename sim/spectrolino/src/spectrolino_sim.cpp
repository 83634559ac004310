#include "colorlab/sim/spectrolino_sim.hpp"

#include "colorlab/core/error.hpp"
#include "colorlab/sim/scene.hpp"

namespace colorlab::sim {

namespace sp = wire::spectrolino;

namespace {

std::uint8_t exec_error_from_json(const nlohmann::json& v) {
  if (v.is_number_integer()) {
    int c = v.get<int>();
    if (c < 0 || c > 255) throw Error(ErrorClass::bad_parameter, "exec_error must be 0..255");
    return static_cast<std::uint8_t>(c);
  }
  if (!v.is_string()) throw Error(ErrorClass::bad_parameter, "exec_error must be a code or a name");
  std::string s = v.get<std::string>();
  if (s == "lamp_failure") return sp::exec_err::LampFailure;
  if (s == "measuring_disabled") return sp::exec_err::MeasDisabled;
  if (s == "no_valid_measurement") return sp::exec_err::NoValidMeas;
  if (s == "too_much_light") return sp::exec_err::RemOverflow;
  if (s == "hardware_failure") return sp::exec_err::HardwareFailure;
  if (s == "not_ready") return sp::exec_err::NotReady;
  if (s == "filter_out_of_position") return sp::exec_err::FilterOutOfPos;
  try {
    std::size_t used = 0;
    int c = std::stoi(s, &used, 16);
    if (used == s.size() && c >= 0 && c <= 255) return static_cast<std::uint8_t>(c);
  } catch (const std::exception&) {
  }
  throw Error(ErrorClass::bad_parameter, "exec_error '" + s + "' is neither a hex code nor a known name",
              "names: lamp_failure, measuring_disabled, no_valid_measurement, too_much_light, hardware_failure, "
              "not_ready, filter_out_of_position");
}

}  // namespace

void from_json(const nlohmann::json& j, SpectrolinoFaults& f) {
  from_json(j, f.link);
  if (j.contains("exec_error")) {
    if (j["exec_error"].is_null() || j["exec_error"] == "") {
      f.exec_error.reset();
    } else {
      f.exec_error = exec_error_from_json(j["exec_error"]);
    }
  }
  f.exec_error_once = j.value("exec_error_once", f.exec_error_once);
  f.calibration_lifetime_s = j.value("calibration_lifetime_s", f.calibration_lifetime_s);
  if (f.calibration_lifetime_s < 0) throw Error(ErrorClass::bad_parameter, "calibration_lifetime_s must be >= 0");
  f.expire_calibration = j.value("expire_calibration", false);
  f.power_cycle = j.value("power_cycle", false);
}

void to_json(nlohmann::json& j, const SpectrolinoFaults& f) {
  to_json(j, f.link);
  j["exec_error"] = f.exec_error ? nlohmann::json(*f.exec_error) : nlohmann::json(nullptr);
  j["exec_error_once"] = f.exec_error_once;
  j["calibration_lifetime_s"] = f.calibration_lifetime_s;
}

SpectrolinoSim::SpectrolinoSim(boost::asio::any_io_executor executor, const Scene& scene, SpectrolinoConfig config,
                               std::uint64_t seed, double time_scale)
    : PtyDevice(executor, "spectrolino", time_scale),
      scene_(scene),
      model_(scene, std::move(config), seed),
      fault_rng_(seed ^ 0x5eed'fa17ull) {}

void SpectrolinoSim::set_faults(const SpectrolinoFaults& faults) {
  faults_ = faults;
  model_.set_forced_exec_error(faults.exec_error, faults.exec_error_once);
  model_.set_calibration_lifetime(faults.calibration_lifetime_s);
  if (faults.expire_calibration) model_.expire_calibration();
  if (faults.power_cycle) {
    model_.power_cycle();
    clear_replies();
    line_.clear();
  }
  // One-shot faults act now and are not kept, so a later fault command does not repeat them.
  faults_.expire_calibration = false;
  faults_.power_cycle = false;
  if (faults.link.disconnect_s > 0) silent_until_ = scene_.clock().now() + faults.link.disconnect_s;
  faults_.link.disconnect_s = 0;
}

bool SpectrolinoSim::link_down() const {
  return faults_.link.silent || (silent_until_ >= 0 && scene_.clock().now() < silent_until_);
}

void SpectrolinoSim::on_bytes(std::string_view bytes) {
  for (char c : bytes) {
    if (c == ';') {
      line_.assign(1, c);  // a start character begins a new record, whatever came before
    } else if (c == '\n') {
      if (!line_.empty()) {
        std::string line = std::move(line_);
        line_.clear();
        handle_line(line);
      }
    } else if (line_.size() < 2048) {
      line_ += c;
    }
  }
}

void SpectrolinoSim::handle_line(const std::string& line) {
  if (client_settings().baud != static_cast<unsigned>(model_.baud()) || link_down()) {
    ++ignored_;
    return;
  }
  SpectrolinoReply r = model_.handle(line);
  ++answered_;
  if (r.bytes.empty()) return;
  double extra = 0;
  auto out = apply_link_faults(faults_.link, std::move(r.bytes), fault_rng_, extra, 1, 2);
  if (!out) return;
  reply(std::move(*out), r.device_seconds + extra, line.size() + 1);
}

}  // namespace colorlab::sim
