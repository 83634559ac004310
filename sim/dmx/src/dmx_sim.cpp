#include "colorlab/sim/dmx_sim.hpp"

#include <set>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/sim/scene.hpp"

namespace colorlab::sim {

namespace en = wire::enttec;

void validate(const DmxConfig& config) {
  std::set<int> used;
  for (const auto& m : config.channels) {
    if (m.channel < 1 || m.channel > static_cast<int>(en::kMaxSlots)) {
      throw Error(ErrorClass::bad_parameter,
                  "dmx channel " + std::to_string(m.channel) + " (" + m.target + ") is outside 1..512");
    }
    if (!used.insert(m.channel).second) {
      throw Error(ErrorClass::bad_parameter, "dmx channel " + std::to_string(m.channel) + " is mapped twice");
    }
    if (m.target != "dimmer") lamp_from_string(m.target);  // throws for unknown lamps
  }
}

DmxSim::DmxSim(boost::asio::any_io_executor executor, Scene& scene, DmxConfig config, std::uint64_t seed,
               double time_scale)
    : PtyDevice(executor, "dmx", time_scale), scene_(scene), config_(std::move(config)), rng_(seed) {
  validate(config_);
}

void DmxSim::set_faults(const LinkFaults& faults) {
  faults_ = faults;
  // disconnect_s is one-shot: it silences the widget from now on, and a later fault command does not repeat it.
  if (faults.disconnect_s > 0) silent_until_ = scene_.clock().now() + faults.disconnect_s;
  faults_.disconnect_s = 0;
}

bool DmxSim::link_down() const {
  return faults_.silent || (silent_until_ >= 0 && scene_.clock().now() < silent_until_);
}

void DmxSim::on_bytes(std::string_view bytes) {
  auto frames = parser_.feed(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()));
  for (const auto& f : frames) {
    // A pulled USB cable loses whatever the host sent meanwhile.
    if (link_down()) continue;
    try {
      handle(f);
    } catch (const Error& e) {
      ++rejected_;
      log::debug("sim", std::string("dmx: rejected request: ") + e.what());
    }
  }
}

void DmxSim::send(std::vector<std::uint8_t> frame, std::size_t request_bytes) {
  double extra = 0;
  auto out = apply_link_faults(faults_, std::string(frame.begin(), frame.end()), rng_, extra, 1, 1);
  if (!out) return;
  reply(std::move(*out), kReplySeconds + extra, request_bytes);
}

void DmxSim::handle(const en::Frame& f) {
  std::size_t request_bytes = f.payload.size() + 5;
  switch (f.label) {
    case en::label::GetWidgetParameters: {
      std::uint16_t n = en::decode_get_parameters_request(f);
      auto p = params_;
      p.user_config.resize(std::min<std::size_t>(n, 508), 0);
      send(en::get_parameters_reply(p), request_bytes);
      break;
    }
    case en::label::SetWidgetParameters: params_ = en::decode_set_parameters_request(f); break;
    case en::label::SendDmx: {
      auto packet = en::decode_send_dmx(f);
      if (packet.start_code != en::kDmxStartCode) break;  // alternate start codes carry no dimmer levels
      ++packets_;
      std::vector<std::uint8_t> previous = universe_;
      universe_ = packet.slots;
      if (universe_ != previous) apply_universe(previous);
      break;
    }
    case en::label::GetSerialNumber:
      if (!f.payload.empty()) throw Error(ErrorClass::protocol_error, "serial request carries data");
      send(en::serial_reply(en::bcd_serial(config_.serial_decimal)), request_bytes);
      break;
    default: break;  // genuine widgets ignore labels they do not implement (OLA's 77/78 included)
  }
}

void DmxSim::apply_universe(const std::vector<std::uint8_t>& previous) {
  // Only channels whose level changed act, so a lamp that dropped out stays dark until it comes back
  // or its channel is switched again. A short frame sets only the channels it carries.
  for (const auto& m : config_.channels) {
    std::size_t i = static_cast<std::size_t>(m.channel - 1);
    if (i >= universe_.size()) continue;
    std::uint8_t v = universe_[i];
    if (i < previous.size() && previous[i] == v && packets_ > 1) continue;
    if (m.target == "dimmer") {
      double pct = v * 100.0 / 255.0;
      if (std::abs(scene_.dimmer() - pct) > 1e-9) scene_.set_dimmer(pct);
    } else {
      Lamp lamp = lamp_from_string(m.target);
      bool on = v >= 128;
      if (scene_.lamp_on(lamp) != on) scene_.set_lamp(lamp, on);
    }
  }
}

}  // namespace colorlab::sim
