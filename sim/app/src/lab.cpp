#include "colorlab/sim/lab.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <string_view>
#include <utility>

#include "colorlab/core/error.hpp"
#include <boost/asio/steady_timer.hpp>

#include "colorlab/core/log.hpp"
#include "colorlab/sim/aravis/gv_fake_camera.hpp"
#include "colorlab/sim/capture_scratch.hpp"
#include "colorlab/sim/aravis/scene_fill.hpp"
#include "colorlab/sim/camera/camera_model.hpp"
#include "colorlab/sim/clock.hpp"
#include "colorlab/sim/dmx_sim.hpp"
#include "colorlab/sim/dslr/dslr_server.hpp"
#include "colorlab/sim/ls110_sim.hpp"
#include "colorlab/sim/relay_socket_server.hpp"
#include "colorlab/sim/scene.hpp"
#include "colorlab/sim/spectrolino_sim.hpp"

namespace colorlab::sim {

using nlohmann::json;

namespace {

// Where sockets go when the configuration names none: beside the default control socket.
std::filesystem::path runtime_path(const std::string& name) {
  const char* runtime = std::getenv("XDG_RUNTIME_DIR");
  std::filesystem::path dir = runtime && *runtime ? runtime : std::filesystem::temp_directory_path();
  return dir / ("colorlab-sim-" + std::to_string(::getpid()) + "-" + name);
}

// A fault command's relay keys over the board's current faults (unmentioned keys stay).
RelayBoardFaults relay_faults(const json& f, RelayBoardFaults now) {
  for (const auto& [key, value] : f.items()) {
    if (key == "stuck_mask") now.stuck_mask = value.get<std::uint8_t>();
    else if (key == "unplugged") now.unplugged = value.get<bool>();
    else if (key == "replug_after_opens") now.replug_after_opens = value.get<int>();
    else throw Error(ErrorClass::bad_parameter, "unknown relay fault '" + key + "'", "stuck_mask, unplugged, replug_after_opens");
  }
  return now;
}

}  // namespace

struct Lab::Impl {
  boost::asio::io_context* io = nullptr;
  LabConfig config;
  std::shared_ptr<SimClock> clock;
  std::unique_ptr<Scene> scene;
  std::shared_ptr<Ls110Sim> ls110;
  std::shared_ptr<SpectrolinoSim> spectrolino;
  std::shared_ptr<DmxSim> dmx;
  std::shared_ptr<camera::CameraModel> camera_model;  // the GenICam camera's
  std::shared_ptr<camera::CameraModel> dslr_model;
  std::unique_ptr<aravis::GvFakeCamera> genicam;
  std::string genicam_absent;  // why the GenICam camera asked for did not start, announced as "absent"
  std::unique_ptr<dslr::DslrServer> dslr;
  std::filesystem::path dslr_temp_dir;  // created here, removed with the lab
  std::shared_ptr<RelayBoard> relay_board;
  std::unique_ptr<RelaySocketServer> relay;
  std::vector<std::shared_ptr<boost::asio::steady_timer>> dropouts;
  json drifts = json::object();  // lamp → the drift last commanded
  int aim_row = 0, aim_col = 0;

  // Lamp dropout: the lamp goes dark for `seconds` of simulated time, then relights (and warms up
  // again) if nothing switched it off meanwhile.
  json lamp_dropout(const json& spec) {
    if (!spec.is_object()) throw Error(ErrorClass::bad_parameter, "lamp_dropout must be {\"lamp\":NAME,\"seconds\":S}");
    Lamp lamp = lamp_from_string(spec.value("lamp", std::string()));
    double seconds = spec.value("seconds", 0.0);
    if (seconds <= 0) throw Error(ErrorClass::bad_parameter, "lamp_dropout.seconds must be > 0");
    bool was_on = scene->lamp_on(lamp);
    scene->set_lamp(lamp, false);
    if (was_on) {
      auto timer = std::make_shared<boost::asio::steady_timer>(*io, clock->to_real(seconds));
      dropouts.push_back(timer);
      timer->async_wait([this, lamp, timer](boost::system::error_code ec) {
        if (!ec) scene->set_lamp(lamp, true);
        std::erase(dropouts, timer);
      });
    }
    return {{"lamp", to_string(lamp)}, {"seconds", seconds}, {"was_on", was_on}};
  }

  // Lamp drift: the lamp's output moves by `rate_pct_per_min` % of normal per simulated minute for `seconds`,
  // then holds there (`then` = "hold", an overheated or aged tube at its new equilibrium) or comes back at the
  // same rate ("return", the overheating clears). Rate 0 clears a drift.
  json lamp_drift(const json& spec) {
    if (!spec.is_object()) {
      throw Error(ErrorClass::bad_parameter,
                  "lamp_drift must be {\"lamp\":NAME,\"rate_pct_per_min\":R,\"seconds\":S,\"then\":\"hold\"|\"return\"}");
    }
    Lamp lamp = lamp_from_string(spec.value("lamp", std::string()));
    const double rate = spec.value("rate_pct_per_min", 0.0), seconds = spec.value("seconds", 0.0);
    const std::string then = spec.value("then", std::string("hold"));
    if (then != "hold" && then != "return") throw Error(ErrorClass::bad_parameter, "lamp_drift.then must be \"hold\" or \"return\"");
    if (!(seconds >= 0) || !(std::abs(rate) <= 100)) {
      throw Error(ErrorClass::bad_parameter, "lamp_drift needs seconds >= 0 and a rate of at most 100 %/min either way");
    }
    LampDrift drift{clock->now(), rate / 100.0 / 60.0, seconds, then == "return"};
    scene->set_lamp_drift(lamp, drift);
    drifts[std::string(to_string(lamp))] = {{"rate_pct_per_min", rate}, {"seconds", seconds}, {"then", then}, {"start_s", drift.start_s}};
    return {{"lamp", to_string(lamp)}, {"rate_pct_per_min", rate}, {"seconds", seconds}, {"then", then}, {"start_s", drift.start_s}};
  }

  // The cabinet's faults, which may ride along in any instrument's fault command: done, answered, removed.
  void cabinet_faults(json& faults, json& answer) {
    if (!faults.is_object()) return;
    if (faults.contains("lamp_dropout")) answer["lamp_dropout"] = lamp_dropout(faults["lamp_dropout"]);
    if (faults.contains("lamp_drift")) answer["lamp_drift"] = lamp_drift(faults["lamp_drift"]);
    faults.erase("lamp_dropout");
    faults.erase("lamp_drift");
  }

  // Ground truth of the drifts started: each lamp's drift as commanded and its output factor now.
  json drift_truth() const {
    json out = json::object();
    for (const auto& [lamp, spec] : drifts.items()) {
      json t = spec;
      t["factor"] = scene->drift_factor(lamp_from_string(lamp));
      out[lamp] = t;
    }
    return out;
  }

  json spectrolino_truth() const {
    const auto& m = spectrolino->model();
    auto [x, y] = m.head_mm();
    json t{{"head_mm", {x, y}},
           {"on_tile", m.head_on_tile()},
           {"calibrated", m.calibrated()},
           {"baud", m.baud()},
           {"measurements", m.measurements()},
           {"lines_answered", spectrolino->lines_answered()},
           {"lines_ignored", spectrolino->lines_ignored()}};
    auto r = m.true_reflectance();
    t["true_spectrum"] = std::vector<float>(r.begin(), r.end());
    auto surface = m.surface_reflectance();
    t["surface_spectrum"] = std::vector<float>(surface.begin(), surface.end());
    if (auto last = m.last_spectrum()) t["last_spectrum"] = std::vector<float>(last->begin(), last->end());
    return t;
  }

  // The camera models by instrument id ("" = every camera): what camera_view aims and floor_truth describes.
  std::vector<std::pair<std::string, std::shared_ptr<camera::CameraModel>>> cameras(const std::string& id) const {
    std::vector<std::pair<std::string, std::shared_ptr<camera::CameraModel>>> out;
    if (genicam && camera_model && (id.empty() || id == config.genicam.id)) out.emplace_back(config.genicam.id, camera_model);
    if (dslr && dslr_model && (id.empty() || id == config.dslr.id)) out.emplace_back(config.dslr.id, dslr_model);
    if (out.empty()) throw Error(ErrorClass::not_found, "no simulated camera '" + id + "'", "use a camera id from the announcement");
    return out;
  }

  // The lens's f-number a camera photographs at now: the DSLR's setting; the GenICam camera's fixed lens.
  double f_number_of(const std::string& id) const {
    if (dslr && id == config.dslr.id) return dslr->body().settings().value("aperture", 4.0);
    return 4.0;  // scene_camera_options' default: a machine-vision lens at f/4
  }

  // {placement = {rotation_deg, tilt_deg, swing_deg, fill, shift_x, shift_y} | "configured", lens = {fx, fy, cx, cy,
  // k1, k2}}: where the operator put the chart, and the camera's lens in OpenCV's conventions.
  static json placement_json(const camera::CameraModel& m) {
    const auto l = m.lens();
    json placed = "configured";
    if (const auto p = m.chart_placement()) {
      placed = {
          {"rotation_deg", p->rotation_deg},
          {"tilt_deg", p->tilt_deg},
          {"swing_deg", p->swing_deg},
          {"fill", p->fill},
          {"shift_x", p->shift_x},
          {"shift_y", p->shift_y},
      };
    }
    return {{"placement", placed}, {"lens", {{"fx", l.fx}, {"fy", l.fy}, {"cx", l.cx}, {"cy", l.cy}, {"k1", l.k1}, {"k2", l.k2}}}};
  }

  static camera::ChartPlacement placement_from(const json& spec) {
    const char* keys = "rotation_deg, tilt_deg, swing_deg, fill, shift_x, shift_y";
    if (!spec.is_object())
      throw Error(ErrorClass::bad_parameter, "place_chart: placement must be \"configured\" or a table", std::string("keys: ") + keys);
    camera::ChartPlacement p;
    for (const auto& [key, value] : spec.items()) {
      static constexpr std::pair<std::string_view, double camera::ChartPlacement::*> kFields[] = {
          {"rotation_deg", &camera::ChartPlacement::rotation_deg},
          {"tilt_deg", &camera::ChartPlacement::tilt_deg},
          {"swing_deg", &camera::ChartPlacement::swing_deg},
          {"fill", &camera::ChartPlacement::fill},
          {"shift_x", &camera::ChartPlacement::shift_x},
          {"shift_y", &camera::ChartPlacement::shift_y},
      };
      double* field = nullptr;
      for (const auto& [name, member] : kFields)
        if (key == name) field = &(p.*member);
      if (!field) throw Error(ErrorClass::bad_parameter, "place_chart: unknown placement key '" + key + "'", std::string("keys: ") + keys);
      if (!value.is_number()) throw Error(ErrorClass::bad_parameter, "place_chart: placement." + key + " must be a number");
      *field = value.get<double>();
    }
    return p;
  }

  static json corners_json(const camera::CameraModel& m) {
    json c = json::array();
    for (const auto& p : m.floor_corners_px()) c.push_back({p[0], p[1]});
    return c;
  }

  // Ground truth of the floor as one camera sees it now: every spot of the 8 × 20 grid with its true luminance (the
  // LS-110's physics, no noise), the LS-110's σ there, its pixel and the floor view's relative illumination there; the
  // floor's corners in the image; the camera's noise model (docs/simulator.md, "floor_truth").
  json floor_truth(const std::string& id) const {
    auto [name, m] = cameras(id).front();
    const double f_number = f_number_of(name);
    json spots = json::array();
    for (int r = 0; r < floor_rows; ++r)
      for (int c = 0; c < floor_cols; ++c) {
        const auto [x, y] = Scene::floor_spot_position_mm(r, c);
        const double l = scene->floor_luminance(r, c);
        const auto px = m->floor_point_px(x, y);
        spots.push_back({
            {"row", r},
            {"col", c},
            {"x_mm", x},
            {"y_mm", y},
            {"luminance", l},
            {"ls110_sigma", scene->luminance_noise_sigma(l)},
            {"px", {px[0], px[1]}},
            {"relative_illumination", m->relative_illumination(px[0], px[1], f_number, camera::CameraModel::View::floor)},
        });
      }
    const auto& cc = m->config();
    json lamps = json::array();
    for (auto l : scene->lamps_on()) lamps.push_back(to_string(l));
    return {
        {"ok", true},
        {"instrument", name},
        {"view", m->view() == camera::CameraModel::View::floor ? "floor" : "chart"},
        {"width", m->width()},
        {"height", m->height()},
        {"f_number", f_number},
        {"floor_corners_px", corners_json(*m)},
        {"lamps_on", lamps},
        {"dimmer", scene->dimmer()},
        {"noise", {
                      {"gain_dn_per_e_iso100", cc.gain_dn_per_e_iso100},
                      {"read_noise_e", cc.read_noise_e},
                      {"adc_noise_dn", cc.adc_noise_dn},
                      {"dark_current_e_per_s", cc.dark_current_e_per_s},
                      {"prnu_sigma", cc.prnu_sigma},
                      {"dsnu_sigma_dn", cc.dsnu_sigma_dn},
                      {"column_offset_sigma_dn", cc.column_offset_sigma_dn},
                      {"black_level", 256},
                  }},
        {"spots", spots},
    };
  }

  Ls110Truth ls110_truth() const {
    double l = scene->floor_luminance(aim_row, aim_col);
    return {l, scene->luminance_noise_sigma(l)};
  }
};

Lab::Lab(boost::asio::io_context& io, LabConfig config) : impl_(std::make_unique<Impl>()) {
  auto& d = *impl_;
  d.io = &io;
  d.config = std::move(config);
  d.clock = std::make_shared<SimClock>(d.config.time_scale);
  SceneConfig sc;
  sc.seed = d.config.seed;
  sc.chart_file = d.config.chart_file;
  for (const auto& name : d.config.lamps_on) sc.lamps_on_at_start.push_back(lamp_from_string(name));
  sc.dimmer_percent_at_start = d.config.dimmer_percent;
  if (d.config.geometric_floor) sc.geometric_cabinet = d.config.cabinet;
  d.scene = std::make_unique<Scene>(sc, d.clock);

  if (d.config.ls110.enabled) {
    d.aim_row = d.config.ls110.aim_row;
    d.aim_col = d.config.ls110.aim_col;
    d.scene->floor_luminance(d.aim_row, d.aim_col);  // validates the aim now, not at the first reading
    d.ls110 = std::make_shared<Ls110Sim>(
        io.get_executor(), [impl = &d] { return impl->ls110_truth(); },
        d.scene->stream_seed("ls110"), d.config.time_scale);
    d.ls110->set_faults(d.config.ls110.faults.get<Ls110Faults>());
    d.ls110->start();
  }

  if (d.config.spectrolino.enabled) {
    d.spectrolino = std::make_shared<SpectrolinoSim>(io.get_executor(), *d.scene, d.config.spectrolino.device,
                                                     d.scene->stream_seed("spectrolino"), d.config.time_scale);
    if (d.config.spectrolino.head_mm) {
      d.spectrolino->model().place_head(d.config.spectrolino.head_mm->first, d.config.spectrolino.head_mm->second);
    } else if (!d.config.spectrolino.device.table) {
      d.spectrolino->model().place_on_tile();
    }
    d.spectrolino->set_faults(d.config.spectrolino.faults.get<SpectrolinoFaults>());
    d.spectrolino->start();
  }

  if (d.config.dmx.enabled) {
    d.dmx = std::make_shared<DmxSim>(io.get_executor(), *d.scene, d.config.dmx.device, d.scene->stream_seed("dmx"),
                                     d.config.time_scale);
    d.dmx->set_faults(d.config.dmx.faults.get<LinkFaults>());
    d.dmx->start();
  }

  if (d.config.genicam.enabled) {
    // A camera that cannot start (GVCP port taken by another simulator, no loopback) leaves the rest of
    // the lab running; the announcement then simply lists no GenICam camera.
    try {
      // The Lab owns the scene and outlives the camera, so the model gets a non-owning pointer.
      std::shared_ptr<const Scene> scene(std::shared_ptr<const Scene>{}, d.scene.get());
      camera::CameraConfig cc;
      cc.width = d.config.genicam.width;
      cc.height = d.config.genicam.height;
      d.camera_model = std::make_shared<camera::CameraModel>(scene, cc);
      auto options = aravis::scene_camera_options(d.camera_model);
      options.address = d.config.genicam.address;
      options.serial = d.config.genicam.serial;
      d.genicam = std::make_unique<aravis::GvFakeCamera>(options);
    } catch (const Error& e) {
      log::warning("sim", std::string("GenICam camera not started: ") + e.what());
      d.genicam.reset();
      d.genicam_absent = std::string(e.what()) + (e.hint().empty() ? "" : " (" + e.hint() + ")");
    }
  }

  if (d.config.dslr.enabled) start_dslr();
  if (d.config.relay.enabled) start_relay();
}

void Lab::start_dslr() {
  auto& d = *impl_;
  const auto& dc = d.config.dslr;
  // The Lab owns the scene and outlives the camera, so the model gets a non-owning pointer.
  std::shared_ptr<const Scene> scene(std::shared_ptr<const Scene>{}, d.scene.get());
  camera::CameraConfig cc;
  cc.width = dc.width;
  cc.height = dc.height;
  cc.seed = d.scene->stream_seed("dslr");  // another body than the GenICam camera: its own noise and defects
  if (dc.pose == DslrLabConfig::Pose::seeded) cc.pose = camera::random_chart_pose(dc.pose_seed.value_or(d.scene->stream_seed("dslr-pose")));
  if (dc.pose == DslrLabConfig::Pose::given) cc.pose = dc.given_pose;
  dslr::DslrBodyConfig bc;
  bc.serial = dc.serial;
  bc.transfer_s = dc.transfer_s;
  if (dc.capture_dir) {
    bc.capture_dir = *dc.capture_dir;
  } else {
    const auto root = d.config.scratch_dir.value_or(std::filesystem::temp_directory_path());
    std::error_code ec;
    std::filesystem::create_directories(root, ec);
    if (ec) throw Error(ErrorClass::io_error, "simulated DSLR: cannot create the scratch directory " + root.string() + ": " + ec.message(),
                        "check colorlab-sim --scratch-dir (colorlabd: its state directory) and its permissions");
    // A simulator killed with SIGKILL could not remove its card folder; its successor does.
    for (const auto& gone : reclaim_dead_capture_dirs(root)) log::info("sim", "removed a killed simulator's DSLR folder " + gone.string());
    d.dslr_temp_dir = default_capture_dir(root, ::getpid());
    bc.capture_dir = d.dslr_temp_dir;
  }
  d.dslr_model = std::make_shared<camera::CameraModel>(scene, cc);
  auto body = std::make_shared<dslr::DslrBody>(d.dslr_model, bc);
  d.dslr = std::make_unique<dslr::DslrServer>(d.io->get_executor(), body, dc.socket.value_or(runtime_path("dslr.sock")), d.clock);
  d.dslr->start();
  if (!dc.faults.empty()) d.dslr->set_faults(dc.faults);
}

void Lab::start_relay() {
  auto& d = *impl_;
  const auto& rc = d.config.relay;
  d.relay_board = std::make_shared<RelayBoard>(rc.relays, rc.board_id, "/dev/hidraw-sim0");
  // The board starts with the relays of the lamps the scene starts with closed, so both agree.
  std::uint8_t mask = 0;
  for (const auto& [lamp, relay] : rc.lamps) {
    if (d.scene->lamp_on(lamp_from_string(lamp))) mask |= static_cast<std::uint8_t>(1u << (relay - 1));
  }
  d.relay_board->set_mask(mask);
  // The board's relays drive the cabinet's lamps, so the LS-110 and the cameras see what it switches.
  auto on_switch = [impl = &d](int relay, bool on) {
    for (const auto& [lamp, r] : impl->config.relay.lamps) {
      if (r == relay) impl->scene->set_lamp(lamp_from_string(lamp), on);
    }
  };
  d.relay = std::make_unique<RelaySocketServer>(d.io->get_executor(), d.relay_board, rc.socket.value_or(runtime_path("relay.sock")), on_switch);
  d.relay->start();
  if (!rc.faults.empty()) d.relay_board->set_faults(relay_faults(rc.faults, d.relay_board->faults()));
}

Lab::~Lab() {
  impl_->genicam.reset();
  if (impl_->dslr) impl_->dslr->stop();
  if (impl_->relay) impl_->relay->stop();
  if (!impl_->dslr_temp_dir.empty()) {
    std::error_code ec;
    std::filesystem::remove_all(impl_->dslr_temp_dir, ec);
  }
  if (impl_->ls110) impl_->ls110->stop();
  if (impl_->spectrolino) impl_->spectrolino->stop();
  if (impl_->dmx) impl_->dmx->stop();
  for (auto& t : impl_->dropouts) t->cancel();
}

Scene& Lab::scene() { return *impl_->scene; }
const LabConfig& Lab::config() const { return impl_->config; }

json Lab::announcement() const {
  const auto& d = *impl_;
  json instruments = json::array();
  if (d.ls110) {
    instruments.push_back({{"id", d.config.ls110.id},
                           {"kind", "ls110"},
                           {"model", "Konica Minolta LS-110"},
                           {"port", d.ls110->port_path()},
                           {"serial", {{"baud", 4800}, {"framing", "7E2"}}},
                           {"simulated", true}});
  }
  if (d.spectrolino) {
    const auto& dev = d.config.spectrolino.device;
    instruments.push_back(
        {{"id", d.config.spectrolino.id},
         {"kind", "spectrolino"},
         {"model", dev.table ? "GretagMacbeth Spectrolino on SpectroScan T" : "GretagMacbeth Spectrolino"},
         {"port", d.spectrolino->port_path()},
         {"serial", {{"baud", dev.power_on_baud}, {"framing", "8N1"}}},
         {"simulated", true},
         {"driver_options", {{"power_on_baud", dev.power_on_baud}, {"table", dev.table}}}});
  }
  if (d.dmx) {
    json channels = json::object();
    for (const auto& m : d.config.dmx.device.channels) channels[m.target] = m.channel;
    instruments.push_back({{"id", d.config.dmx.id},
                           {"kind", "dmx"},
                           {"model", "Enttec DMX USB Pro"},
                           {"port", d.dmx->port_path()},
                           {"serial", {{"baud", 115200}, {"framing", "8N1"}}},
                           {"simulated", true},
                           {"driver_options", {{"channels", channels}}}});
  }
  if (d.genicam) {
    instruments.push_back({{"id", d.config.genicam.id},
                           {"kind", "genicam"},
                           {"model", "Aravis GigE Vision fake camera (simulated EOS 20D sensor, BayerRG12)"},
                           {"address", d.genicam->address()},
                           {"device_id", d.genicam->address()},
                           {"serial", d.genicam->serial()},
                           {"simulated", true}});
  }
  if (d.dslr) {
    instruments.push_back({{"id", d.config.dslr.id},
                           {"kind", "simdslr"},
                           {"model", "Simulated Canon EOS 20D (tethered; DNG, JPEG, TIFF)"},
                           {"port", d.dslr->socket_path().string()},
                           {"serial", d.config.dslr.serial},
                           {"capture_dir", d.dslr->body().config().capture_dir.string()},
                           {"simulated", true}});
  }
  if (d.relay) {
    json lamps = json::object();
    for (const auto& [lamp, relay] : d.config.relay.lamps) lamps[lamp] = relay;
    instruments.push_back({{"id", d.config.relay.id},
                           {"kind", "hidrelay"},
                           {"model", "dcttech USBRelay" + std::to_string(d.config.relay.relays) + " (HID feature reports over a socket)"},
                           {"port", "unix:" + d.relay->socket_path().string()},
                           {"simulated", true},
                           {"driver_options", {{"lamps", lamps}, {"board_id", d.config.relay.board_id}}}});
  }
  json announced{{"colorlab_sim", 1},
                 {"pid", ::getpid()},
                 {"seed", d.config.seed},
                 {"time_scale", d.config.time_scale},
                 {"instruments", instruments}};
  // Asked for and not started: a client lists it as absent with this reason instead of losing it.
  if (!d.genicam && !d.genicam_absent.empty()) {
    announced["absent"] = json::array({{{"id", d.config.genicam.id},
                                        {"kind", "genicam"},
                                        {"address", d.config.genicam.address},
                                        {"reason", d.genicam_absent}}});
  }
  return announced;
}

json Lab::control(const json& command) {
  auto& d = *impl_;
  try {
    if (!command.is_object() || !command.contains("cmd") || !command["cmd"].is_string()) {
      throw Error(ErrorClass::bad_parameter, "a control command is an object with a string 'cmd'");
    }
    std::string cmd = command["cmd"];
    if (cmd == "announce") return {{"ok", true}, {"announcement", announcement()}};
    if (cmd == "truth") {
      json t{{"ok", true}, {"sim_time_s", d.clock->now()}, {"dimmer", d.scene->dimmer()}};
      json lamps = json::array();
      for (auto l : d.scene->lamps_on()) lamps.push_back(to_string(l));
      t["lamps_on"] = lamps;
      json warmup = json::object();
      for (auto l : d.scene->lamps_on()) warmup[std::string(to_string(l))] = d.scene->warmup_factor(l);
      t["warmup"] = warmup;          // 1 = fully warm
      t["drift"] = d.drift_truth();  // per lamp a drift was started on: the command and its factor now (1 = none)
      json output = json::object();
      for (auto l : d.scene->lamps_on()) output[std::string(to_string(l))] = d.scene->output_factor(l);
      t["output"] = output;  // warm-up × drift: each lit lamp's output relative to normal
      if (d.dslr) t["dslr"] = d.dslr->truth();
      if (d.relay) {
        t["relay"] = {
            {"board_id", d.relay_board->board_id()},
            {"mask", d.relay_board->mask()},
            {"requests", d.relay->requests()},
            {"socket", d.relay->socket_path().string()},
        };
      }
      if (d.ls110) {
        auto lt = d.ls110_truth();
        t["ls110"] = {
            {"luminance", lt.luminance},
            {"noise_sigma", lt.noise_sigma},
            {"aim", {d.aim_row, d.aim_col}},
            {"readings_served", d.ls110->readings_served()},
        };
      }
      if (d.spectrolino) {
        t["spectrolino"] = d.spectrolino_truth();
        t["spectrolino"]["serial"] = std::to_string(d.config.spectrolino.device.serial);
        if (d.config.spectrolino.device.table) t["spectrolino"]["table_serial"] = std::to_string(d.config.spectrolino.device.table_serial);
      }
      if (d.genicam) {
        // what a GigE Vision client should find and how many frames the camera has filled for it
        t["genicam"] = {
            {"address", d.genicam->address()},
            {"serial", d.genicam->serial()},
            {"plugged_in", d.genicam->plugged_in()},
            {"frames_filled", d.genicam->frames_filled()},
            {"sensor", {d.camera_model->width(), d.camera_model->height()}},
        };
      }
      if (d.dmx) {
        const auto& u = d.dmx->universe();
        // The serial as printed on the widget's label: what an operator confirms (colorlab doctor).
        t["dmx"] = {{"serial", std::to_string(d.config.dmx.device.serial_decimal)},
                    {"packets", d.dmx->packets()},
                    {"slots", std::vector<int>(u.begin(), u.begin() + static_cast<long>(std::min<std::size_t>(u.size(), 16)))},
                    {"slot_count", u.size()},  // of the last label 6 packet
                    {"bad_frames", d.dmx->bad_frames()},
                    {"rejected_requests", d.dmx->rejected_requests()},
                    // as the last label 4 set them, so a client's parameter writes are checked at the widget
                    {"parameters", {
                                       {"break_time", d.dmx->parameters().break_time},
                                       {"mab_time", d.dmx->parameters().mab_time},
                                       {"output_rate", d.dmx->parameters().output_rate},
                                   }}};
      }
      return t;
    }
    if (cmd == "fault") {
      std::string id = command.value("instrument", std::string());
      json faults = command.value("faults", json::object());
      json answer{{"ok", true}};
      if (id == "cabinet" || (faults.is_object() && (faults.contains("lamp_dropout") || faults.contains("lamp_drift")))) {
        d.cabinet_faults(faults, answer);
        if (id == "cabinet") {
          if (!faults.empty()) throw Error(ErrorClass::bad_parameter, "unknown cabinet fault '" + faults.begin().key() + "'", "lamp_dropout, lamp_drift");
          return answer;
        }
      }
      if (d.ls110 && id == d.config.ls110.id) {
        d.ls110->set_faults(faults.get<Ls110Faults>());
        answer["faults"] = d.ls110->faults();
        return answer;
      }
      if (d.spectrolino && id == d.config.spectrolino.id) {
        // Unmentioned faults keep their current values, so faults can be added one at a time.
        auto f = d.spectrolino->faults();
        from_json(faults, f);
        d.spectrolino->set_faults(f);
        answer["faults"] = d.spectrolino->faults();
        return answer;
      }
      if (d.genicam && id == d.config.genicam.id) {
        if (faults.value("capture_timeout", false)) d.genicam->stall();
        answer["faults"] = {{"capture_timeout", faults.value("capture_timeout", false)}};
        return answer;
      }
      if (d.dslr && id == d.config.dslr.id) {
        answer["faults"] = d.dslr->set_faults(faults);
        return answer;
      }
      if (d.relay && id == d.config.relay.id) {
        d.relay_board->set_faults(relay_faults(faults, d.relay_board->faults()));
        const auto f = d.relay_board->faults();
        answer["faults"] = {{"stuck_mask", f.stuck_mask}, {"unplugged", f.unplugged}, {"replug_after_opens", f.replug_after_opens}};
        return answer;
      }
      if (d.dmx && id == d.config.dmx.id) {
        auto f = d.dmx->faults();
        from_json(faults, f);
        d.dmx->set_faults(f);
        answer["faults"] = d.dmx->faults();
        return answer;
      }
      throw Error(ErrorClass::not_found, "no simulated instrument '" + id + "' takes faults",
                  "use an id from the announcement, or \"cabinet\" for lamp_dropout or lamp_drift alone");
    }
    if (cmd == "place") {
      if (!d.spectrolino || command.value("instrument", d.config.spectrolino.id) != d.config.spectrolino.id) {
        throw Error(ErrorClass::not_found, "no simulated Spectrolino to place");
      }
      auto& m = d.spectrolino->model();
      std::string target = command.value("target", std::string("xy"));
      if (target == "white_tile") {
        m.place_on_tile();
      } else if (target == "patch") {
        auto idx = d.scene->chart().index_of(command.value("patch", std::string()));
        if (!idx) throw Error(ErrorClass::bad_parameter, "no chart patch '" + command.value("patch", std::string()) + "'");
        m.place_on_patch(*idx);
      } else if (target == "xy") {
        m.place_head(command.value("x_mm", -1.0), command.value("y_mm", -1.0));
      } else {
        throw Error(ErrorClass::bad_parameter, "place target must be white_tile, patch or xy");
      }
      return {{"ok", true}, {"spectrolino", d.spectrolino_truth()}};
    }
    if (cmd == "camera_truth") {
      if (!d.dslr || command.value("instrument", d.config.dslr.id) != d.config.dslr.id) {
        throw Error(ErrorClass::not_found, "no simulated DSLR '" + command.value("instrument", std::string()) + "'");
      }
      std::optional<std::string> file;
      if (command.contains("file")) file = command["file"].get<std::string>();
      json t = d.dslr->shot_truth(file);
      t.update(Impl::placement_json(*d.dslr_model));  // the lens a calibration must find, and where the chart is now
      t["ok"] = true;
      return t;
    }
    if (cmd == "aim") {
      int row = command.value("row", -1), col = command.value("col", -1);
      d.scene->floor_luminance(row, col);  // throws for spots off the grid
      d.aim_row = row;
      d.aim_col = col;
      return {{"ok", true}};
    }
    if (cmd == "camera_view") {
      // The operator's "aim_camera": the chart out of the cabinet and the camera at the whole floor, or back.
      const std::string view = command.value("view", std::string());
      if (view != "floor" && view != "chart") throw Error(ErrorClass::bad_parameter, "camera_view: view must be \"floor\" or \"chart\"");
      json cams = json::object();
      for (auto& [name, m] : d.cameras(command.value("instrument", std::string()))) {
        m->set_view(view == "floor" ? camera::CameraModel::View::floor : camera::CameraModel::View::chart);
        cams[name] = {{"view", view}, {"width", m->width()}, {"height", m->height()}, {"floor_corners_px", Impl::corners_json(*m)}};
      }
      return {{"ok", true}, {"view", view}, {"cameras", cams}};
    }
    if (cmd == "place_chart") {
      // The operator's "place_chart" (the lens-calibration campaign): the chart at another pose before the cameras, or
      // back where the configuration put it ("configured"). The lens stays each camera's.
      const json& spec = command.contains("placement") ? command["placement"] : json();
      std::optional<camera::ChartPlacement> placement;
      if (!(spec.is_string() && spec.get<std::string>() == "configured")) placement = Impl::placement_from(spec);
      json cams = json::object();
      for (auto& [name, m] : d.cameras(command.value("instrument", std::string()))) {
        m->place_chart(placement);
        cams[name] = Impl::placement_json(*m);
      }
      return {{"ok", true}, {"cameras", cams}};
    }
    if (cmd == "floor_truth") return d.floor_truth(command.value("instrument", std::string()));
    if (cmd == "lamp") {
      d.scene->set_lamp(lamp_from_string(command.value("lamp", std::string())), command.value("on", true));
      return {{"ok", true}};
    }
    if (cmd == "dimmer") {
      d.scene->set_dimmer(command.value("percent", -1.0));
      return {{"ok", true}};
    }
    throw Error(ErrorClass::bad_parameter, "unknown control command '" + cmd + "'",
                "commands: announce, truth, camera_truth, floor_truth, camera_view, place_chart, fault, place, aim, lamp, dimmer");
  } catch (const Error& e) {
    return {{"ok", false}, {"error", to_string(e.cls())}, {"message", e.info().message}, {"hint", e.hint()}};
  } catch (const json::exception& e) {
    return {{"ok", false}, {"error", "bad_parameter"}, {"message", e.what()}};
  }
}

}  // namespace colorlab::sim
