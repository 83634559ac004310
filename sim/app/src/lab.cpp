#include "colorlab/sim/lab.hpp"

#include <unistd.h>

#include "colorlab/core/error.hpp"
#include "colorlab/sim/clock.hpp"
#include "colorlab/sim/ls110_sim.hpp"
#include "colorlab/sim/scene.hpp"

namespace colorlab::sim {

using nlohmann::json;

struct Lab::Impl {
  LabConfig config;
  std::shared_ptr<SimClock> clock;
  std::unique_ptr<Scene> scene;
  std::shared_ptr<Ls110Sim> ls110;
  int aim_row = 0, aim_col = 0;

  Ls110Truth ls110_truth() const {
    double l = scene->floor_luminance(aim_row, aim_col);
    return {l, scene->luminance_noise_sigma(l)};
  }
};

Lab::Lab(boost::asio::io_context& io, LabConfig config) : impl_(std::make_unique<Impl>()) {
  auto& d = *impl_;
  d.config = std::move(config);
  d.clock = std::make_shared<SimClock>(d.config.time_scale);
  SceneConfig sc;
  sc.seed = d.config.seed;
  sc.chart_file = d.config.chart_file;
  for (const auto& name : d.config.lamps_on) sc.lamps_on_at_start.push_back(lamp_from_string(name));
  sc.dimmer_percent_at_start = d.config.dimmer_percent;
  d.scene = std::make_unique<Scene>(sc, d.clock);

  if (d.config.ls110.enabled) {
    d.aim_row = d.config.ls110.aim_row;
    d.aim_col = d.config.ls110.aim_col;
    d.scene->floor_luminance(d.aim_row, d.aim_col);  // validates the aim now, not at the first reading
    d.ls110 = std::make_shared<Ls110Sim>(io.get_executor(), [impl = &d] { return impl->ls110_truth(); },
                                         d.scene->stream_seed("ls110"), d.config.time_scale);
    d.ls110->set_faults(d.config.ls110.faults.get<Ls110Faults>());
    d.ls110->start();
  }
}

Lab::~Lab() {
  if (impl_->ls110) impl_->ls110->stop();
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
  return {{"colorlab_sim", 1},
          {"pid", ::getpid()},
          {"seed", d.config.seed},
          {"time_scale", d.config.time_scale},
          {"instruments", instruments}};
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
      if (d.ls110) {
        auto lt = d.ls110_truth();
        t["ls110"] = {{"luminance", lt.luminance}, {"noise_sigma", lt.noise_sigma},
                      {"aim", {d.aim_row, d.aim_col}}, {"readings_served", d.ls110->readings_served()}};
      }
      return t;
    }
    if (cmd == "fault") {
      std::string id = command.value("instrument", std::string());
      if (d.ls110 && id == d.config.ls110.id) {
        d.ls110->set_faults(command.value("faults", json::object()).get<Ls110Faults>());
        return {{"ok", true}, {"faults", d.ls110->faults()}};
      }
      throw Error(ErrorClass::not_found, "no simulated instrument '" + id + "' takes faults");
    }
    if (cmd == "aim") {
      int row = command.value("row", -1), col = command.value("col", -1);
      d.scene->floor_luminance(row, col);  // throws for spots off the grid
      d.aim_row = row;
      d.aim_col = col;
      return {{"ok", true}};
    }
    if (cmd == "lamp") {
      d.scene->set_lamp(lamp_from_string(command.value("lamp", std::string())), command.value("on", true));
      return {{"ok", true}};
    }
    if (cmd == "dimmer") {
      d.scene->set_dimmer(command.value("percent", -1.0));
      return {{"ok", true}};
    }
    throw Error(ErrorClass::bad_parameter, "unknown control command '" + cmd + "'",
                "commands: announce, truth, fault, aim, lamp, dimmer");
  } catch (const Error& e) {
    return {{"ok", false}, {"error", to_string(e.cls())}, {"message", e.info().message}, {"hint", e.hint()}};
  } catch (const json::exception& e) {
    return {{"ok", false}, {"error", "bad_parameter"}, {"message", e.what()}};
  }
}

}  // namespace colorlab::sim
