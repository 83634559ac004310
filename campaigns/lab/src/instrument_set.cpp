#include "colorlab/campaigns/instrument_set.hpp"

#include <filesystem>

#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

void InstrumentSet::add(std::shared_ptr<drivers::Instrument> instrument) {
  if (find(instrument->id())) {
    throw Error(ErrorClass::bad_parameter, "two instruments share the id '" + instrument->id() + "'",
                "give each [[instrument]] in the configuration its own id");
  }
  instruments_.push_back(std::move(instrument));
}

std::shared_ptr<drivers::Instrument> InstrumentSet::find(const std::string& id) const {
  for (const auto& i : instruments_) {
    if (i->id() == id) return i;
  }
  return nullptr;
}

void InstrumentSet::add_absent(AbsentInstrument instrument) {
  if (find(instrument.id)) return;  // the driver is the better account of it
  for (const auto& a : absent_) {
    if (a.id == instrument.id) return;  // the first reason is the one that kept it out
  }
  absent_.push_back(std::move(instrument));
}

bool InstrumentSet::port_missing(const drivers::Instrument& instrument) {
  if (instrument.state() != drivers::InstrumentState::disconnected) return false;
  const auto port = instrument.identity().port;
  std::error_code ec;
  // A symlink udev has not made yet, or one left dangling when the adapter went.
  return port.starts_with('/') && !std::filesystem::exists(port, ec);
}

std::optional<std::string> InstrumentSet::absence(const drivers::Instrument& instrument) {
  if (instrument.state() != drivers::InstrumentState::disconnected) return std::nullopt;
  if (port_missing(instrument)) {
    return "its port " + instrument.identity().port +
           " is not there (not plugged in, or no udev rule made the link); it connects when the port appears";
  }
  if (auto p = instrument.last_problem(); !p.empty()) return p;
  return std::nullopt;
}

nlohmann::json InstrumentSet::describe_all() const {
  auto items = nlohmann::json::array();
  for (const auto& i : instruments_) {
    auto j = drivers::describe(*i);
    if (auto reason = absence(*i)) {
      j["state"] = "absent";
      j["reason"] = *reason;
    }
    items.push_back(std::move(j));
  }
  for (const auto& a : absent_) {
    items.push_back({{"id", a.id},
                     {"kind", a.kind},
                     {"model", ""},
                     {"serial", ""},
                     {"firmware", ""},
                     {"port", a.port},
                     {"simulated", a.simulated},
                     {"state", "absent"},
                     {"reason", a.reason},
                     {"capabilities", nlohmann::json::array()},
                     {"calibration", nlohmann::json::array()}});
  }
  return items;
}

void InstrumentSet::throw_missing(drivers::Capability capability) {
  throw Error(ErrorClass::not_found,
              "no configured instrument offers " + std::string(drivers::to_string(capability)),
              "add one to the configuration, or start colorlabd without --config to use the simulated lab");
}

}  // namespace colorlab::campaigns
