#include "colorlab/campaigns/instrument_set.hpp"

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

void InstrumentSet::throw_missing(drivers::Capability capability) {
  throw Error(ErrorClass::not_found,
              "no configured instrument offers " + std::string(drivers::to_string(capability)),
              "add one to the configuration, or start colorlabd without --config to use the simulated lab");
}

}  // namespace colorlab::campaigns
