#include "colorlab/drivers/factory.hpp"

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/aravis_camera.hpp"
#include "colorlab/drivers/camera/camera_instrument.hpp"
#include "colorlab/drivers/camera/gphoto2_camera.hpp"
#include "colorlab/drivers/camera/sim_dslr_camera.hpp"
#include "colorlab/drivers/enttec_dmx.hpp"
#include "colorlab/drivers/hid_relay.hpp"
#include "colorlab/drivers/hidapi_transport.hpp"
#include "colorlab/drivers/socket_hid_transport.hpp"
#include "colorlab/drivers/ls110.hpp"
#include "colorlab/drivers/spectrolino.hpp"

namespace colorlab::drivers {

namespace {

namespace sl = colorlab::wire::spectrolino;

std::shared_ptr<Instrument> make_ls110(boost::asio::any_io_executor executor, const InstrumentConfig& c) {
  Ls110Options o;
  o.id = c.id;
  o.port = c.port;
  o.simulated = c.simulated;
  if (c.options.contains("reply_timeout_ms")) o.reply_timeout = std::chrono::milliseconds(c.options["reply_timeout_ms"].get<int>());
  if (c.options.contains("attempts")) o.attempts = c.options["attempts"].get<int>();
  return std::make_shared<Ls110>(executor, o);
}

std::chrono::milliseconds ms(const nlohmann::json& o, const char* key, std::chrono::milliseconds fallback) {
  return o.contains(key) ? std::chrono::milliseconds(o[key].get<int>()) : fallback;
}

ReconnectPolicy reconnect_policy(const nlohmann::json& o) {
  ReconnectPolicy p;
  if (o.contains("reconnect_attempts")) p.max_attempts = o["reconnect_attempts"].get<int>();
  p.initial_backoff = ms(o, "reconnect_backoff_ms", p.initial_backoff);
  return p;
}

sl::Illuminant illuminant_option(const std::string& name) {
  for (std::uint8_t v = 0; v <= 0x23; ++v) {
    if (sl::valid_illuminant(v) && sl::illuminant_name(static_cast<sl::Illuminant>(v)) == name) return static_cast<sl::Illuminant>(v);
  }
  throw Error(ErrorClass::bad_parameter, "unknown Spectrolino illuminant '" + name + "'", "use A, C, D50, D65, F1..F12");
}

std::shared_ptr<Instrument> make_spectrolino(boost::asio::any_io_executor executor, const InstrumentConfig& c) {
  SpectrolinoOptions o;
  o.id = c.id;
  o.port = c.port;
  o.simulated = c.simulated;
  const auto& j = c.options;
  if (j.contains("max_baud")) o.max_baud = j["max_baud"].get<unsigned>();
  if (j.contains("initialise_table")) o.initialise_table = j["initialise_table"].get<bool>();
  if (j.contains("illuminant")) o.illuminant = illuminant_option(j["illuminant"].get<std::string>());
  if (j.contains("observer")) {
    int deg = j["observer"].get<int>();
    if (deg != 2 && deg != 10) throw Error(ErrorClass::bad_parameter, "observer must be 2 or 10 (degrees)");
    o.observer = deg == 10 ? sl::Observer::Deg10 : sl::Observer::Deg2;
  }
  if (j.contains("white_base")) {
    auto wb = j["white_base"].get<std::string>();
    if (wb != "absolute" && wb != "paper") throw Error(ErrorClass::bad_parameter, "white_base must be 'absolute' or 'paper'");
    o.white_base = wb == "paper" ? sl::WhiteBase::Paper : sl::WhiteBase::Absolute;
  }
  if (j.contains("white_tile")) o.white_tile = static_cast<std::uint8_t>(j["white_tile"].get<int>() - 1);
  if (j.contains("calibration_interval")) o.reflective_cal_interval = j["calibration_interval"].get<int>();
  if (j.contains("attempts")) o.command_attempts = j["attempts"].get<int>();
  if (j.contains("patch_attempts")) o.patch_attempts = j["patch_attempts"].get<int>();
  o.timeouts.command = ms(j, "command_timeout_ms", o.timeouts.command);
  o.timeouts.measure = ms(j, "measure_timeout_ms", o.timeouts.measure);
  o.timeouts.move = ms(j, "move_timeout_ms", o.timeouts.move);
  o.reconnect = reconnect_policy(j);
  return std::make_shared<Spectrolino>(executor, o);
}

bool allow_multiple(const nlohmann::json& o) { return o.value("allow_multiple_lamps", false); }

std::shared_ptr<Instrument> make_dmx(boost::asio::any_io_executor executor, const InstrumentConfig& c) {
  EnttecDmxOptions o;
  o.id = c.id;
  o.port = c.port;
  o.simulated = c.simulated;
  const auto& j = c.options;
  // "lamps" (+ "dimmer_channel") in colorlabd.toml; colorlab-sim announces one "channels" map with "dimmer" in it.
  nlohmann::json lamps = j.contains("lamps") ? j["lamps"] : j.value("channels", nlohmann::json::object());
  if (lamps.contains("dimmer")) {
    o.dimmer_channel = lamps["dimmer"].get<int>();
    lamps.erase("dimmer");
  }
  if (lamps.empty()) throw Error(ErrorClass::bad_parameter, "instrument '" + c.id + "' needs a lamps = {D65 = 1, ...} channel map");
  o.lamps = LampMap::from_json(lamps, 512, allow_multiple(j));
  if (j.contains("dimmer_channel")) o.dimmer_channel = j["dimmer_channel"].get<int>();
  if (j.contains("ramp_per_second")) o.ramp_per_second = j["ramp_per_second"].get<double>();
  o.settle = ms(j, "settle_ms", o.settle);
  o.frame_interval = ms(j, "frame_interval_ms", o.frame_interval);
  o.reply_timeout = ms(j, "reply_timeout_ms", o.reply_timeout);
  if (j.contains("slots")) o.slots = j["slots"].get<std::size_t>();
  o.reconnect = reconnect_policy(j);
  return std::make_shared<EnttecDmx>(executor, o);
}

std::shared_ptr<Instrument> make_hidrelay(boost::asio::any_io_executor executor, const InstrumentConfig& c) {
  HidRelayOptions o;
  o.id = c.id;
  o.simulated = c.simulated;
  const auto& j = c.options;
  if (!j.contains("lamps")) throw Error(ErrorClass::bad_parameter, "instrument '" + c.id + "' needs a lamps = {D65 = 1, ...} relay map");
  o.lamps = LampMap::from_json(j["lamps"], 8, allow_multiple(j));
  o.expected_board_id = j.value("board_id", std::string{});
  if (j.contains("switch_attempts")) o.switch_attempts = j["switch_attempts"].get<int>();
  o.reconnect = reconnect_policy(j);
  // port "auto" takes the first dcttech board, "unix:/path" the simulated lab's board behind its
  // socket; otherwise a /dev/hidrawN path.
  std::unique_ptr<HidTransport> transport;
  if (c.port.starts_with("unix:")) {
    transport = std::make_unique<SocketHidTransport>(c.port.substr(5), ms(j, "reply_timeout_ms", std::chrono::milliseconds(1000)));
  } else {
    transport = std::make_unique<HidapiTransport>(c.port == "auto" ? std::string{} : c.port);
  }
  return std::make_shared<HidRelay>(executor, std::move(transport), o);
}

}  // namespace

std::shared_ptr<Instrument> make_genicam(const InstrumentConfig& c) {
  camera::AravisOptions o;
  o.device_id = c.port;
  if (c.options.contains("black_level")) o.black_level = c.options["black_level"].get<std::uint16_t>();
  if (c.options.contains("frame_timeout_ms")) o.frame_timeout = std::chrono::milliseconds(c.options["frame_timeout_ms"].get<int>());
  if (c.options.contains("region")) {
    const auto& r = c.options["region"];
    o.region = camera::Region{r.at(0).get<int>(), r.at(1).get<int>(), r.at(2).get<int>(), r.at(3).get<int>()};
  }
  return std::make_shared<camera::CameraInstrument>(c.id, c.port, c.simulated, std::make_unique<camera::AravisCamera>(o));
}

namespace {

// The tethered DSLR through libgphoto2: port "auto" (the first camera libgphoto2 detects),
// "usb:BUS,DEV", or "disk:/dir" (the Directory Browse camlib, for tests without a camera).
std::shared_ptr<Instrument> make_gphoto2(const InstrumentConfig& c) {
  camera::Gphoto2Options o;
  o.port = c.port == "auto" ? std::string{} : c.port;
  const auto& j = c.options;
  if (j.contains("model")) o.model = j["model"].get<std::string>();
  if (j.contains("keep_dir")) o.keep_dir = j["keep_dir"].get<std::string>();
  if (j.contains("delete_on_card")) o.delete_on_card = j["delete_on_card"].get<bool>();
  if (j.contains("pair_wait_ms")) o.pair_wait_ms = j["pair_wait_ms"].get<int>();
  o.call_timeout = ms(j, "call_timeout_ms", o.call_timeout);
  return std::make_shared<camera::CameraInstrument>(c.id, c.port, c.simulated, std::make_unique<camera::Gphoto2Camera>(o));
}

// The simulated lab's DSLR: port is the socket path colorlab-sim announces.
std::shared_ptr<Instrument> make_simdslr(const InstrumentConfig& c) {
  camera::SimDslrOptions o;
  o.socket_path = c.port;
  const auto& j = c.options;
  if (j.contains("keep_dir")) o.keep_dir = j["keep_dir"].get<std::string>();
  o.request_timeout = ms(j, "request_timeout_ms", o.request_timeout);
  o.capture_timeout = ms(j, "capture_timeout_ms", o.capture_timeout);
  return std::make_shared<camera::CameraInstrument>(c.id, c.port, true, std::make_unique<camera::SimDslrCamera>(o));
}

}  // namespace

std::vector<std::string> known_instrument_kinds() {
  return {"ls110", "spectrolino", "dmx", "hidrelay", "genicam", "gphoto2", "simdslr"};
}

std::shared_ptr<Instrument> make_instrument(boost::asio::any_io_executor executor, const InstrumentConfig& config) {
  if (config.id.empty()) throw Error(ErrorClass::bad_parameter, "an instrument entry has no id");
  if (config.port.empty()) throw Error(ErrorClass::bad_parameter, "instrument '" + config.id + "' has no port");
  try {
    if (config.kind == "ls110") return make_ls110(executor, config);
    if (config.kind == "spectrolino") return make_spectrolino(executor, config);
    if (config.kind == "dmx") return make_dmx(executor, config);
    if (config.kind == "hidrelay") return make_hidrelay(executor, config);
    if (config.kind == "genicam") return make_genicam(config);
    if (config.kind == "gphoto2") return make_gphoto2(config);
    if (config.kind == "simdslr") return make_simdslr(config);
  } catch (const nlohmann::json::exception& e) {
    throw Error(ErrorClass::bad_parameter, "instrument '" + config.id + "': bad option: " + e.what());
  }
  std::string kinds;
  for (const auto& k : known_instrument_kinds()) kinds += (kinds.empty() ? "" : ", ") + k;
  throw Error(ErrorClass::bad_parameter, "instrument '" + config.id + "' has unknown kind '" + config.kind + "'",
              "known kinds: " + kinds);
}

}  // namespace colorlab::drivers
