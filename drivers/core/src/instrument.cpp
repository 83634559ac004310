#include "colorlab/drivers/instrument.hpp"

#include <algorithm>
#include <cmath>

#include "colorlab/drivers/lab_capabilities.hpp"

#include <nlohmann/json.hpp>

namespace colorlab::drivers {

std::string_view to_string(InstrumentState s) {
  switch (s) {
    case InstrumentState::disconnected: return "disconnected";
    case InstrumentState::initialising: return "initialising";
    case InstrumentState::ready: return "ready";
    case InstrumentState::busy: return "busy";
    case InstrumentState::needs_calibration: return "needs_calibration";
    case InstrumentState::needs_operator: return "needs_operator";
    case InstrumentState::fault: return "fault";
  }
  return "fault";
}

std::string_view to_string(Capability c) {
  switch (c) {
    case Capability::luminance: return "luminance";
    case Capability::reflectance_spectrum: return "reflectance_spectrum";
    case Capability::emission_spectrum: return "emission_spectrum";
    case Capability::transmission_spectrum: return "transmission_spectrum";
    case Capability::xy_table: return "xy_table";
    case Capability::lamp_switching: return "lamp_switching";
    case Capability::dimmer: return "dimmer";
    case Capability::camera: return "camera";
  }
  return "unknown";
}

nlohmann::json describe(const Instrument& instrument) {
  auto ident = instrument.identity();
  nlohmann::json caps = nlohmann::json::array();
  for (auto c : instrument.capabilities()) caps.push_back(to_string(c));
  nlohmann::json cals = nlohmann::json::array();
  for (const auto& c : instrument.calibration()) {
    nlohmann::json j{{"type", c.type}, {"valid", c.valid}};
    if (c.readings_left) j["readings_left"] = *c.readings_left;
    if (c.valid_until) {
      j["valid_until_unix_ms"] =
          std::chrono::duration_cast<std::chrono::milliseconds>(c.valid_until->time_since_epoch()).count();
    }
    cals.push_back(std::move(j));
  }
  nlohmann::json j{{"id", instrument.id()},
                   {"kind", ident.kind},
                   {"model", ident.model},
                   {"serial", ident.serial},
                   {"firmware", ident.firmware},
                   {"port", ident.port},
                   {"simulated", ident.simulated},
                   {"state", to_string(instrument.state())},
                   {"capabilities", std::move(caps)},
                   {"calibration", std::move(cals)}};
  if (auto p = instrument.last_problem(); !p.empty()) j["problem"] = p;
  // The light cabinet as it is now: which lamps are lit and at what level (percent), so a client (the web
  // console's Lab page) sees it without a campaign asking.
  const auto* lamps = dynamic_cast<const LampController*>(&instrument);
  const auto* dimmer = dynamic_cast<const Dimmer*>(&instrument);
  if (lamps || dimmer) {
    nlohmann::json lab = nlohmann::json::object();
    std::vector<std::string> names, lit;
    if (lamps) {
      names = lamps->lamp_names();
      lit = lamps->lamps_on();
      nlohmann::json on = nlohmann::json::object();
      for (const auto& n : names) on[n] = std::find(lit.begin(), lit.end(), n) != lit.end();
      lab["lamps"] = on;
    }
    if (dimmer && !names.empty()) {
      auto percent = [](double level) { return std::round(level * 1000.0) / 10.0; };
      nlohmann::json levels = nlohmann::json::object();
      for (const auto& n : names) levels[n] = percent(dimmer->level(n));
      lab["levels"] = levels;
      // The level of the lamp that is lit, when exactly one is (the cabinet's usual state).
      if (lit.size() == 1) lab["dimmer"] = percent(dimmer->level(lit.front()));
    }
    j["lab"] = std::move(lab);
  }
  return j;
}

}  // namespace colorlab::drivers
