#include "colorlab/drivers/factory.hpp"

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/ls110.hpp"

namespace colorlab::drivers {

namespace {

std::shared_ptr<Instrument> make_ls110(boost::asio::any_io_executor executor, const InstrumentConfig& c) {
  Ls110Options o;
  o.id = c.id;
  o.port = c.port;
  o.simulated = c.simulated;
  if (c.options.contains("reply_timeout_ms")) o.reply_timeout = std::chrono::milliseconds(c.options["reply_timeout_ms"].get<int>());
  if (c.options.contains("attempts")) o.attempts = c.options["attempts"].get<int>();
  return std::make_shared<Ls110>(executor, o);
}

}  // namespace

std::vector<std::string> known_instrument_kinds() { return {"ls110"}; }

std::shared_ptr<Instrument> make_instrument(boost::asio::any_io_executor executor, const InstrumentConfig& config) {
  if (config.id.empty()) throw Error(ErrorClass::bad_parameter, "an instrument entry has no id");
  if (config.port.empty()) throw Error(ErrorClass::bad_parameter, "instrument '" + config.id + "' has no port");
  try {
    if (config.kind == "ls110") return make_ls110(executor, config);
  } catch (const nlohmann::json::exception& e) {
    throw Error(ErrorClass::bad_parameter, "instrument '" + config.id + "': bad option: " + e.what());
  }
  std::string kinds;
  for (const auto& k : known_instrument_kinds()) kinds += (kinds.empty() ? "" : ", ") + k;
  throw Error(ErrorClass::bad_parameter, "instrument '" + config.id + "' has unknown kind '" + config.kind + "'",
              "known kinds: " + kinds);
}

}  // namespace colorlab::drivers
