#include "colorlab/drivers/spectrolino.hpp"

#include <cmath>

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/core/log.hpp"

namespace colorlab::drivers {

namespace asio = boost::asio;

namespace {

std::uint16_t tenth_mm(double mm, double max_mm, std::string_view axis) {
  if (!std::isfinite(mm) || mm < 0 || mm > max_mm) {
    throw Error(ErrorClass::bad_parameter, std::string(axis) + " = " + std::to_string(mm) + " mm is outside the table (0–" +
                                               std::to_string(static_cast<int>(max_mm)) + " mm)");
  }
  return static_cast<std::uint16_t>(std::lround(mm * 10.0));
}

std::string hex_byte(std::uint8_t b) { return sl::to_hex(std::vector<std::uint8_t>{b}); }

}  // namespace

Spectrolino::Spectrolino(asio::any_io_executor executor, SpectrolinoOptions options)
    : options_(std::move(options)),
      executor_(executor),
      link_(executor, options_.port),
      protocol_(link_, options_.timeouts, options_.command_attempts),
      reconnector_(executor, options_.reconnect) {
  identity_.kind = "spectrolino";
  identity_.model = "Spectrolino";
  identity_.port = options_.port;
  identity_.simulated = options_.simulated;
}

Spectrolino::~Spectrolino() = default;

Identity Spectrolino::identity() const { return identity_; }

unsigned Spectrolino::baud() const { return link_.is_open() ? link_.settings().baud : 0; }

std::vector<Capability> Spectrolino::capabilities() const {
  std::vector<Capability> caps{Capability::reflectance_spectrum, Capability::emission_spectrum};
  if (topology_ != SpectrolinoTopology::standalone) caps.push_back(Capability::xy_table);
  if (topology_ == SpectrolinoTopology::spectroscan_t) caps.push_back(Capability::transmission_spectrum);
  return caps;
}

int Spectrolino::cal_interval() const {
  return mode_ == SpectralMode::transmission ? options_.transmissive_cal_interval : options_.reflective_cal_interval;
}

std::vector<CalibrationStatus> Spectrolino::calibration() const {
  CalibrationStatus s;
  s.type = mode_ == SpectralMode::emission ? "emission" : "white";
  s.valid = calibrated_ && readings_since_cal_ < cal_interval();
  s.readings_left = calibrated_ ? std::max(0, cal_interval() - readings_since_cal_) : 0;
  return {s};
}

void Spectrolino::fail(const Error& e) {
  last_problem_ = std::string(e.what()) + (e.hint().empty() ? "" : " (" + e.hint() + ")");
  switch (e.cls()) {
    case ErrorClass::needs_operator: state_ = InstrumentState::needs_operator; break;
    case ErrorClass::needs_calibration: state_ = InstrumentState::needs_calibration; break;
    case ErrorClass::misread:
    case ErrorClass::bad_parameter:
    case ErrorClass::unsupported:
    case ErrorClass::conflict:
      state_ = calibrated_ ? InstrumentState::ready : InstrumentState::needs_calibration;
      break;
    case ErrorClass::no_comms: state_ = InstrumentState::disconnected; break;
    default: state_ = InstrumentState::fault; break;
  }
  throw e;
}

void Spectrolino::verify_serial(const std::string& expected) const {
  if (identity_.serial != expected) {
    throw Error(ErrorClass::needs_operator, "after reconnecting, the instrument's serial is " + identity_.serial + ", not " + expected,
                "another instrument is on this port: check the cabling before the chart continues");
  }
}

void Spectrolino::require_table(std::string_view what) const {
  if (topology_ == SpectrolinoTopology::standalone) {
    throw Error(ErrorClass::unsupported, std::string(what) + " needs a SpectroScan table; " + options_.id +
                                             " is a stand-alone Spectrolino");
  }
}

void Spectrolino::require_ready(std::string_view what) {
  if (state_ == InstrumentState::busy) throw Error(ErrorClass::conflict, options_.id + " is busy; cannot " + std::string(what));
  if (!link_.is_open()) {
    throw Error(ErrorClass::no_comms, options_.id + " is not connected; cannot " + std::string(what), "connect it first");
  }
}

// ---------------------------------------------------------------- connect

asio::awaitable<void> Spectrolino::connect() {
  state_ = InstrumentState::initialising;
  calibrated_ = false;
  readings_since_cal_ = 0;
  try {
    // The last negotiated speed first: after a daemon restart the devices are usually still there.
    // 28800 is left out as Argyll does: termios has no such standard speed (EINVAL on Linux).
    std::vector<unsigned> speeds{std::min(options_.max_baud, 57600u), 9600, 19200, 4800, 2400, 1200, 600, 300};
    std::vector<unsigned> unique;
    for (unsigned s : speeds) {
      if (s <= options_.max_baud && std::find(unique.begin(), unique.end(), s) == unique.end()) unique.push_back(s);
    }
    auto found = co_await protocol_.scan(unique);
    log::debug("spectrolino", options_.port + ": found at " + std::to_string(found.baud) + " baud");
    if (found.topology == SpectrolinoTopology::standalone) {
      topology_ = SpectrolinoTopology::standalone;
      co_await negotiate_standalone(found.baud);
    } else {
      co_await negotiate_table(found.baud);
    }
    co_await identify();
    co_await apply_parameters();
    mode_ = SpectralMode::reflectance;
    state_ = InstrumentState::needs_calibration;
    last_problem_.clear();
  } catch (const Error& e) {
    link_.close();
    fail(e);
  }
}

void Spectrolino::disconnect() {
  link_.close();
  state_ = InstrumentState::disconnected;
}

asio::awaitable<void> Spectrolino::download(const sl::Bytes& body, std::string_view what) {
  auto answer = co_await protocol_.transact(body, options_.timeouts.command, what);
  try {
    auto head = sl::answer_head(answer);
    if (head.scan || head.code != sl::ans::DownloadError) {
      throw Error(ErrorClass::protocol_error, std::string(what) + ": expected answer 1F, got " + sl::to_hex(answer));
    }
    sl::throw_on_remote_error(sl::DownloadError::decode(answer).remote_errors, what);
  } catch (const Error& e) {
    protocol_.rethrow(e);
  }
}

asio::awaitable<void> Spectrolino::scan_command(const sl::Bytes& body, std::chrono::milliseconds timeout, std::string_view what) {
  auto answer = co_await protocol_.transact(body, timeout, what);
  try {
    auto head = sl::answer_head(answer);
    if (!head.scan || head.code != sl::scan_ans::ErrorAnswer) {
      throw Error(ErrorClass::protocol_error, std::string(what) + ": expected answer D180, got " + sl::to_hex(answer));
    }
    sl::throw_on_scan_error(sl::ScanErrorAnswer::decode(answer).error, what);
  } catch (const Error& e) {
    protocol_.rethrow(e);
  }
}

asio::awaitable<void> Spectrolino::negotiate_standalone(unsigned found_baud) {
  const unsigned target = std::min(options_.max_baud, 57600u);
  co_await download(sl::req::meas_control_download(sl::ctt::HandshakeHardware), "set hardware handshake");
  if (found_baud != target) {
    auto code = sl::baud_ctt(static_cast<int>(target));
    if (!code) throw Error(ErrorClass::bad_parameter, "the Spectrolino cannot run at " + std::to_string(target) + " baud");
    // The answer may come at either speed or be lost; the ParameterRequest below is the real check.
    co_await protocol_.try_once(sl::req::meas_control_download(*code), options_.timeouts.probe);
  }
  link_.reconfigure(spectrolino_serial_settings(target, FlowControl::hardware));
  link_.discard_input();
  auto answer = co_await protocol_.transact(sl::req::parameter_request(), options_.timeouts.command, "parameter request");
  try {
    sl::ParameterAnswer::decode(answer);
  } catch (const Error& e) {
    protocol_.rethrow(e);
  }
}

asio::awaitable<void> Spectrolino::negotiate_table(unsigned found_baud) {
  const unsigned target = std::min(options_.max_baud, 57600u);
  if (options_.initialise_table) {
    co_await scan_command(sl::req::initialize_device(), options_.timeouts.init, "table initialisation");
  }
  co_await scan_command(sl::req::set_online(), options_.timeouts.command, "set table online");
  co_await scan_command(sl::req::change_handshake(sl::ScanHandshake::Hardware), options_.timeouts.command,
                        "set table handshake");
  if (found_baud != target) {
    auto bt = sl::baud_scan_bt(static_cast<int>(target));
    if (!bt) throw Error(ErrorClass::bad_parameter, "the SpectroScan cannot run at " + std::to_string(target) + " baud");
    co_await protocol_.try_once(sl::req::change_baud(*bt), options_.timeouts.probe);
  }
  link_.reconfigure(spectrolino_serial_settings(target, FlowControl::hardware));
  link_.discard_input();
  auto status = co_await protocol_.transact(sl::req::output_status(), options_.timeouts.command, "table status");
  try {
    sl::StatusAnswer::decode(status);
  } catch (const Error& e) {
    protocol_.rethrow(e);
  }
  co_await scan_command(sl::req::scan_spectrolino(), options_.timeouts.init, "connect table to Spectrolino");
  auto type = co_await protocol_.transact(sl::req::output_type(), options_.timeouts.command, "table type");
  try {
    auto name = sl::TypeAnswer::decode(type).name;
    topology_ = name.rfind("SpectroScanT", 0) == 0 ? SpectrolinoTopology::spectroscan_t : SpectrolinoTopology::spectroscan;
    identity_.model = "Spectrolino on " + std::string(topology_ == SpectrolinoTopology::spectroscan_t ? "SpectroScan T" : "SpectroScan");
  } catch (const Error& e) {
    protocol_.rethrow(e);
  }
}

asio::awaitable<void> Spectrolino::identify() {
  auto dev = co_await protocol_.transact(sl::req::device_data_request(), options_.timeouts.command, "device data");
  auto tid = co_await protocol_.transact(sl::req::target_id_request(), options_.timeouts.command, "target id");
  try {
    auto d = sl::DeviceDataAnswer::decode(dev);
    auto t = sl::TargetIdAnswer::decode(tid);
    if (t.target_tech != sl::kTargetTechSpectrolino || t.name.rfind("Spectrolino", 0) != 0) {
      throw Error(ErrorClass::protocol_error,
                  "the instrument is '" + t.name + "' (target tech " + hex_byte(t.target_tech) + "), not a Spectrolino",
                  "check which instrument is on this port");
    }
    if (t.first_wavelength != sl::kFirstWavelength || t.bands != sl::kSpectrumBands || t.step != sl::kWavelengthStep) {
      throw Error(ErrorClass::protocol_error, "unexpected wavelength grid " + std::to_string(t.first_wavelength) + " nm + " +
                                                  std::to_string(t.bands) + " × " + std::to_string(t.step) + " nm");
    }
    identity_.serial = std::to_string(d.serial);
    identity_.firmware = d.software;
    if (topology_ == SpectrolinoTopology::standalone) identity_.model = t.name;
  } catch (const Error& e) {
    protocol_.rethrow(e);
  }
  if (topology_ != SpectrolinoTopology::standalone) {
    auto ser = co_await protocol_.transact(sl::req::output_serial(), options_.timeouts.command, "table serial");
    auto fw = co_await protocol_.transact(sl::req::output_firmware(), options_.timeouts.command, "table firmware");
    try {
      identity_.serial += "/table:" + std::to_string(sl::SerialNumberAnswer::decode(ser).serial);
      identity_.firmware += "/table:" + sl::SoftwareVersionAnswer::decode(fw).version;
    } catch (const Error& e) {
      protocol_.rethrow(e);
    }
  }
}

asio::awaitable<void> Spectrolino::apply_parameters() {
  co_await download(sl::req::parameter_download(options_.density_standard, options_.white_base, options_.illuminant,
                                                options_.observer),
                    "set colorimetric parameters");
  if (topology_ == SpectrolinoTopology::spectroscan_t) {
    co_await scan_command(sl::req::set_table_mode(sl::TableMode::Reflectance), options_.timeouts.init, "set reflectance mode");
  } else {
    co_await download(sl::req::meas_control_download(sl::ctt::ModeReflectance), "set reflectance mode");
  }
}

asio::awaitable<void> Spectrolino::set_colorimetry(sl::Illuminant il, sl::Observer ob, sl::WhiteBase wb) {
  require_ready("set colorimetry");
  try {
    co_await download(sl::req::parameter_download(options_.density_standard, wb, il, ob), "set colorimetric parameters");
  } catch (const Error& e) {
    fail(e);
  }
  // Only once the instrument accepted them: XYZ must be computed under what the instrument uses.
  options_.illuminant = il;
  options_.observer = ob;
  options_.white_base = wb;
  integrator_.reset();
  integrator_failed_ = false;
}

// ---------------------------------------------------------------- modes and calibration

asio::awaitable<void> Spectrolino::set_mode(SpectralMode mode) {
  require_ready("change mode");
  try {
    if (mode == SpectralMode::transmission && topology_ != SpectrolinoTopology::spectroscan_t) {
      throw Error(ErrorClass::unsupported, "transmission needs a SpectroScan T; a stand-alone Spectrolino can only emulate it");
    }
    if (topology_ == SpectrolinoTopology::spectroscan_t && mode != SpectralMode::emission) {
      co_await scan_command(sl::req::set_table_mode(mode == SpectralMode::transmission ? sl::TableMode::Transmission
                                                                                       : sl::TableMode::Reflectance),
                            options_.timeouts.init, "set table mode");
    } else {
      std::uint8_t code = mode == SpectralMode::emission       ? sl::ctt::ModeEmission
                          : mode == SpectralMode::transmission ? sl::ctt::ModeTransmission
                                                               : sl::ctt::ModeReflectance;
      co_await download(sl::req::meas_control_download(code), "set measuring mode");
    }
    if (mode != mode_) {
      mode_ = mode;
      calibrated_ = false;
      readings_since_cal_ = 0;
    }
    state_ = InstrumentState::needs_calibration;
  } catch (const Error& e) {
    fail(e);
  }
}

asio::awaitable<void> Spectrolino::calibrate() {
  require_ready("calibrate");
  co_await calibrate_now();
}

asio::awaitable<void> Spectrolino::calibrate_now() {
  state_ = InstrumentState::busy;
  try {
    const bool table = topology_ != SpectrolinoTopology::standalone;
    if (table && mode_ != SpectralMode::transmission) {
      co_await scan_command(sl::req::move_to_white(options_.white_tile), options_.timeouts.move, "move to white tile");
      co_await scan_command(sl::req::move_down(), options_.timeouts.move, "lower head");
    }
    auto run_ref = [this](sl::RefMode m, std::uint8_t ok, std::string_view what) -> asio::awaitable<void> {
      auto answer = co_await protocol_.transact(sl::req::exec_ref_measurement(m), options_.timeouts.measure, what, 1);
      try {
        auto code = sl::ExecError::decode(answer).error;
        if (code == sl::exec_err::RemOverflow && topology_ == SpectrolinoTopology::standalone) {
          throw Error(ErrorInfo{
              ErrorClass::needs_operator,
              std::string(what) + ": too much light or wrong white reference",
              "place the Spectrolino on its white calibration tile and calibrate again",
              "spectrolino:" + hex_byte(code),
              {},
              false,
              {},
          });
        }
        sl::throw_on_exec_error(code, what, {ok});
      } catch (const Error& e) {
        protocol_.rethrow(e);
      }
    };
    if (mode_ == SpectralMode::emission) {
      // A reflective white calibration first, then the emission (dark) calibration while the head is
      // still on the white tile (Argyll ss.c order: 4D 9B, 22 09 07, 4D 9D, 22 09 08).
      co_await download(sl::req::meas_control_download(sl::ctt::ModeReflectance), "set reflectance mode");
      co_await run_ref(sl::RefMode::WhiteCalWarn, sl::exec_err::WhiteMeasOK, "white calibration");
      co_await download(sl::req::meas_control_download(sl::ctt::ModeEmission), "set emission mode");
      co_await run_ref(sl::RefMode::EmissionCal, sl::exec_err::EmissionCalOK, "emission calibration");
    } else {
      co_await run_ref(sl::RefMode::WhiteCalWarn, sl::exec_err::WhiteMeasOK, "white calibration");
    }
    if (table && mode_ != SpectralMode::transmission) {
      co_await scan_command(sl::req::move_up(), options_.timeouts.move, "raise head");
    }
    auto params = co_await protocol_.transact(sl::req::parameter_request(), options_.timeouts.command, "parameter request");
    try {
      auto p = sl::ParameterAnswer::decode(params);
      if (p.filter == sl::Filter::Undefined) {
        throw Error(ErrorClass::needs_operator, "the Spectrolino reports an undefined filter",
                    "seat the measuring filter correctly and calibrate again");
      }
    } catch (const Error& e) {
      protocol_.rethrow(e);
    }
    calibrated_ = true;
    readings_since_cal_ = 0;
    ++calibrations_;
    state_ = InstrumentState::ready;
    last_problem_.clear();
  } catch (const Error& e) {
    calibrated_ = false;
    fail(e);
  }
}

// ---------------------------------------------------------------- measurement

SpectralReading Spectrolino::make_reading(const sl::Spectrum& spectrum) {
  SpectralReading r;
  r.mode = mode_;
  r.first_nm = sl::kFirstWavelength;
  r.step_nm = sl::kWavelengthStep;
  r.values.assign(spectrum.begin(), spectrum.end());
  r.time = std::chrono::system_clock::now();
  for (double v : r.values) {
    if (!std::isfinite(v)) {
      throw link_.make_error(ErrorClass::misread, "the spectrum contains a non-finite value", "measure again");
    }
  }
  try {
    if (mode_ == SpectralMode::emission) {
      analysis::SpectralSet set;
      set.wavelengths = analysis::uniform_grid(380, 730, 10);
      set.names = {"sample"};
      set.values = Eigen::Map<const Eigen::RowVectorXd>(r.values.data(), static_cast<Eigen::Index>(r.values.size()));
      // mW/(nm·m²) → W: irradiance-based XYZ with Y in lux.
      auto xyz = analysis::emission_to_xyz(set,
                                           options_.observer == sl::Observer::Deg10 ? analysis::Observer::cie1964_10deg
                                                                                    : analysis::Observer::cie1931_2deg,
                                           0.683);
      r.xyz = std::array<double, 3>{xyz[0].X, xyz[0].Y, xyz[0].Z};
    } else if (!integrator_failed_) {
      if (!integrator_) {
        auto illum = analysis::load_illuminant(sl::illuminant_name(options_.illuminant));
        auto obs = analysis::load_observer(options_.observer == sl::Observer::Deg10 ? analysis::Observer::cie1964_10deg
                                                                                    : analysis::Observer::cie1931_2deg);
        integrator_ = std::make_shared<analysis::ReflectanceIntegrator>(illum, obs, analysis::uniform_grid(380, 730, 10));
      }
      Eigen::RowVectorXd row = Eigen::Map<const Eigen::RowVectorXd>(r.values.data(), static_cast<Eigen::Index>(r.values.size()));
      auto xyz = integrator_->xyz(row);
      r.xyz = std::array<double, 3>{xyz.X, xyz.Y, xyz.Z};
    }
  } catch (const Error& e) {
    // The spectrum is the measurement; XYZ is a convenience. Without standard data, say so once.
    if (!integrator_failed_) log::warning("spectrolino", std::string("no XYZ for readings: ") + e.what());
    integrator_failed_ = mode_ != SpectralMode::emission;
  }
  return r;
}

asio::awaitable<SpectralReading> Spectrolino::read_spectrum_after_exec() {
  auto answer = co_await protocol_.transact(sl::req::spec_parameter_request(sl::SpectrumType::Reflectance),
                                            options_.timeouts.command, "spectrum request");
  try {
    auto s = sl::SpecParameterAnswer::decode(answer);
    sl::throw_on_remote_error(s.remote_errors, "spectrum request");
    if (s.ref_valid != 1) {
      throw Error(ErrorClass::needs_calibration, "the Spectrolino has no valid white reference for this reading",
                  "calibrate on the white tile");
    }
    co_return make_reading(s.spectrum);
  } catch (const Error& e) {
    protocol_.rethrow(e);
  }
}

asio::awaitable<SpectralReading> Spectrolino::measure() {
  require_ready("measure");
  if (!calibrated_) {
    fail(Error(ErrorClass::needs_calibration, options_.id + " has not been calibrated in this mode", "run calibrate() first"));
  }
  state_ = InstrumentState::busy;
  try {
    const bool table = topology_ != SpectrolinoTopology::standalone && mode_ != SpectralMode::transmission;
    if (table) co_await scan_command(sl::req::move_down(), options_.timeouts.move, "lower head");
    auto exec = co_await protocol_.transact(sl::req::exec_measurement(), options_.timeouts.measure, "measurement", 1);
    try {
      sl::throw_on_exec_error(sl::ExecError::decode(exec).error, "measurement");
    } catch (const Error& e) {
      protocol_.rethrow(e);
    }
    auto reading = co_await read_spectrum_after_exec();
    if (table) co_await scan_command(sl::req::move_up(), options_.timeouts.move, "raise head");
    ++readings_since_cal_;
    state_ = InstrumentState::ready;
    co_return reading;
  } catch (const Error& e) {
    fail(e);
  }
}

asio::awaitable<SpectralReading> Spectrolino::measure_patch(const PatchVisit& patch) {
  auto x = tenth_mm(patch.x_mm, kTravel.x_max_mm, "x");
  auto y = tenth_mm(patch.y_mm, kTravel.y_max_mm, "y");
  auto answer = co_await protocol_.transact(sl::req::move_and_measure(x, y), options_.timeouts.move + options_.timeouts.measure,
                                            "move and measure", 1);
  try {
    auto head = sl::answer_head(answer);
    if (head.scan) {
      if (head.code != sl::scan_ans::ErrorAnswer) {
        throw Error(ErrorClass::protocol_error, "move and measure: unexpected answer " + sl::to_hex(answer));
      }
      auto code = sl::ScanErrorAnswer::decode(answer).error;
      sl::throw_on_scan_error(code, "move and measure");
      throw Error(ErrorClass::protocol_error, "move and measure answered 'no error' without a spectrum");
    }
    auto s = sl::SpectrumAnswer::decode(answer);
    sl::throw_on_remote_error(s.remote_errors, "move and measure");
    if (s.ref_valid != 1) {
      throw Error(ErrorClass::needs_calibration, "the Spectrolino has no valid white reference for this reading",
                  "calibrate on the white tile");
    }
    co_return make_reading(s.spectrum);
  } catch (const Error& e) {
    protocol_.rethrow(e);
  }
}

// ---------------------------------------------------------------- table

// Every simple table command: refused without a table or while not ready, a failure recorded
// in the instrument state. `body` is a value, never a temporary inside the co_await (GCC 12).
asio::awaitable<void> Spectrolino::table_command(sl::Bytes body, std::chrono::milliseconds timeout, std::string_view what) {
  require_table(what);
  require_ready(what);
  try {
    co_await scan_command(body, timeout, what);
  } catch (const Error& e) {
    fail(e);
  }
}

asio::awaitable<void> Spectrolino::move_to(double x_mm, double y_mm) {
  require_table("move");
  require_ready("move");
  try {
    co_await scan_command(sl::req::move_absolute(sl::ScanRef::Sensor, tenth_mm(x_mm, kTravel.x_max_mm, "x"), tenth_mm(y_mm, kTravel.y_max_mm, "y")),
                          options_.timeouts.move, "move");
  } catch (const Error& e) {
    fail(e);
  }
}

asio::awaitable<void> Spectrolino::home() { co_await table_command(sl::req::move_home(), options_.timeouts.move, "move home"); }

asio::awaitable<void> Spectrolino::head_up() {
  co_await table_command(sl::req::move_up(), options_.timeouts.move, "raise the head");
}

asio::awaitable<void> Spectrolino::head_down() {
  co_await table_command(sl::req::move_down(), options_.timeouts.move, "lower the head");
}

asio::awaitable<void> Spectrolino::hold_paper(bool hold) {
  sl::Bytes body = hold ? sl::req::hold_paper() : sl::req::release_paper();
  const std::string_view what = hold ? "hold paper" : "release paper";
  co_await table_command(std::move(body), options_.timeouts.command, what);
}

asio::awaitable<TablePosition> Spectrolino::position() {
  require_table("read the position");
  require_ready("read the position");
  try {
    auto answer = co_await protocol_.transact(sl::req::output_position(sl::ScanRef::Sensor), options_.timeouts.command, "position");
    try {
      auto p = sl::PositionAnswer::decode(answer);
      co_return TablePosition{p.x / 10.0, p.y / 10.0, p.z == 1};
    } catch (const Error& e) {
      protocol_.rethrow(e);
    }
  } catch (const Error& e) {
    fail(e);
  }
}

asio::awaitable<TableStatus> Spectrolino::table_status() {
  require_table("read the table status");
  require_ready("read the table status");
  try {
    auto answer = co_await protocol_.transact(sl::req::output_status(), options_.timeouts.command, "table status");
    try {
      auto bits = sl::StatusAnswer::decode(answer).bits;
      namespace st = sl::status;
      co_return TableStatus{(bits & st::Online) != 0, (bits & st::PaperHeld) != 0, (bits & st::EnterPressed) != 0,
                            (bits & st::Digitizing) != 0, (bits & st::KeyAck) != 0};
    } catch (const Error& e) {
      protocol_.rethrow(e);
    }
  } catch (const Error& e) {
    fail(e);
  }
}

asio::awaitable<SpectralReading> Spectrolino::move_and_measure(double x_mm, double y_mm) {
  require_table("move and measure");
  require_ready("move and measure");
  if (!calibrated_) {
    fail(Error(ErrorClass::needs_calibration, options_.id + " has not been calibrated in this mode", "run calibrate() first"));
  }
  state_ = InstrumentState::busy;
  try {
    auto r = co_await measure_patch(PatchVisit{0, x_mm, y_mm});
    ++readings_since_cal_;
    state_ = InstrumentState::ready;
    co_return r;
  } catch (const Error& e) {
    fail(e);
  }
}

asio::awaitable<SpectralReading> Spectrolino::read_chart_patch(const ChartPatchVisit& visit) {
  require_table("read a chart patch");
  require_ready("read a chart patch");
  if (visit.row_length < 1) throw Error(ErrorClass::bad_parameter, "a chart row has at least one patch");
  const PatchVisit patch{visit.index, visit.x_mm, visit.y_mm};
  // Recalibrate at the start of a row rather than let the count run out in the middle of one.
  bool row_start = visit.row_start;
  std::optional<Error> last;
  bool lost_link = false;
  for (int attempt = 1; attempt <= options_.patch_attempts; ++attempt) {
    if (lost_link) {
      // Silence mid-chart usually means a power cycle or a replugged cable: the device is back at
      // its power-on speed without calibration. Reconnect (same instrument only) and carry on.
      lost_link = false;
      // A named std::function, not a temporary inside co_await (GCC 12 double-destroys those).
      const Reconnector::Verify same_instrument = [this, serial = identity_.serial]() -> asio::awaitable<void> {
        verify_serial(serial);
        co_return;
      };
      co_await reconnector_.reconnect(*this, same_instrument);
    }
    const bool row_would_expire = row_start && readings_since_cal_ + visit.row_length > cal_interval();
    try {
      // A failed recalibration counts as a failed try of this patch.
      if (!calibrated_ || row_would_expire || readings_since_cal_ >= cal_interval()) co_await calibrate_now();
      row_start = false;
      state_ = InstrumentState::busy;
      auto r = co_await measure_patch(patch);
      r.attempts = attempt;
      ++readings_since_cal_;
      state_ = InstrumentState::ready;
      co_return r;
    } catch (const Error& e) {
      const bool retry = e.cls() == ErrorClass::misread || e.cls() == ErrorClass::timeout ||
                         e.cls() == ErrorClass::coms_fail || e.cls() == ErrorClass::needs_calibration ||
                         e.cls() == ErrorClass::device_error;
      state_ = InstrumentState::ready;
      if (!retry) fail(e);
      last = e;
      log::warning("spectrolino", options_.id + ": patch " + std::to_string(patch.index) + " attempt " +
                                      std::to_string(attempt) + " failed: " + e.what());
      // After a failed reading the white reference is suspect: recalibrate before trying again.
      calibrated_ = false;
      lost_link = calls_for_reconnect(e);
    }
  }
  if (!last) fail(Error(ErrorClass::bad_parameter, options_.id + ": patch_attempts must be at least 1"));
  ErrorInfo info = last->info();
  info.message = options_.id + ": patch " + std::to_string(patch.index) + " failed " +
                 std::to_string(options_.patch_attempts) + " times: " + info.message;
  info.retryable = false;
  fail(Error(std::move(info)));
}

asio::awaitable<std::vector<SpectralReading>> Spectrolino::read_chart(const ChartLayout& layout, Progress progress) {
  require_table("read a chart");
  require_ready("read a chart");
  auto rows = serpentine_rows(layout);
  int total = 0;
  for (const auto& row : rows) total += static_cast<int>(row.size());
  // Patches are numbered strip by strip and a short last strip only drops the highest numbers.
  std::vector<SpectralReading> out(static_cast<std::size_t>(total));
  int done = 0;
  for (const auto& row : rows) {
    for (std::size_t k = 0; k < row.size(); ++k) {
      const ChartPatchVisit visit{row[k].index, row[k].x_mm, row[k].y_mm, k == 0, static_cast<int>(row.size())};
      out[static_cast<std::size_t>(row[k].index)] = co_await read_chart_patch(visit);
      ++done;
      if (progress) progress(done, total);
    }
  }
  co_return out;
}

}  // namespace colorlab::drivers
