#pragma once
// The instruments a daemon owns, by id. The daemon is their single owner; campaigns borrow them.
// Beside the drivers it keeps the configured instruments that have none (their entry could not be
// made into a driver, or the simulated lab could not start them), so that what did not come up is
// listed with its reason rather than left out.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/drivers/instrument.hpp"

namespace colorlab::campaigns {

struct AbsentInstrument {
  std::string id;
  std::string kind;
  std::string port;
  bool simulated = false;
  std::string reason;  // the error that kept it from coming up, with its hint
};

class InstrumentSet {
 public:
  void add(std::shared_ptr<drivers::Instrument> instrument);
  std::shared_ptr<drivers::Instrument> find(const std::string& id) const;
  const std::vector<std::shared_ptr<drivers::Instrument>>& all() const { return instruments_; }

  // A configured instrument without a driver (an id already taken by a driver is refused).
  void add_absent(AbsentInstrument instrument);
  const std::vector<AbsentInstrument>& absent() const { return absent_; }

  // Why a driver that is down is absent rather than merely disconnected: its port is a device path
  // that is not there, or its last connection failed. Nothing while it is up or never tried.
  static std::optional<std::string> absence(const drivers::Instrument& instrument);
  // Absent because its device path is not there: a campaign cannot use it before it is plugged in.
  static bool port_missing(const drivers::Instrument& instrument);

  // GET /v1/instruments' items (and the event stream's snapshot): every driver as drivers::describe
  // has it — state "absent" with a `reason` when absence() says so — then every absent entry.
  nlohmann::json describe_all() const;

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
  std::vector<AbsentInstrument> absent_;
};

}  // namespace colorlab::campaigns
