#pragma once
// One configuration entry ([[instrument]] in colorlabd.toml, or an endpoint the simulated lab
// announces) becomes one driver instance.
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/drivers/instrument.hpp"

namespace colorlab::drivers {

struct InstrumentConfig {
  std::string id;
  std::string kind;  // "ls110", ...
  std::string port;  // serial device path, camera address, ...
  bool simulated = false;
  nlohmann::json options = nlohmann::json::object();  // driver-specific, validated by the driver
};

// Throws Error{bad_parameter} for an unknown kind or invalid options.
std::shared_ptr<Instrument> make_instrument(boost::asio::any_io_executor executor, const InstrumentConfig& config);
std::vector<std::string> known_instrument_kinds();

}  // namespace colorlab::drivers
