#pragma once
// The instruments a daemon owns, by id. The daemon is their single owner; campaigns borrow them.
#include <memory>
#include <string>
#include <vector>

#include "colorlab/drivers/instrument.hpp"

namespace colorlab::campaigns {

class InstrumentSet {
 public:
  void add(std::shared_ptr<drivers::Instrument> instrument);
  std::shared_ptr<drivers::Instrument> find(const std::string& id) const;
  const std::vector<std::shared_ptr<drivers::Instrument>>& all() const { return instruments_; }

  // The first instrument with the given capability that can be cast to T, or Error{not_found}.
  template <class T>
  std::shared_ptr<T> first_with(drivers::Capability capability) const {
    for (const auto& i : instruments_) {
      for (auto c : i->capabilities()) {
        if (c == capability) {
          if (auto t = std::dynamic_pointer_cast<T>(i)) return t;
        }
      }
    }
    throw_missing(capability);
  }

 private:
  [[noreturn]] static void throw_missing(drivers::Capability capability);
  std::vector<std::shared_ptr<drivers::Instrument>> instruments_;
};

}  // namespace colorlab::campaigns
