#include "colorlab/bringup/relay_check.hpp"

#include <chrono>
#include <future>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/use_future.hpp>

#include "colorlab/bringup/hid_recording.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/drivers/hid_relay.hpp"
#include "colorlab/drivers/hidapi_transport.hpp"
#include "colorlab/drivers/socket_hid_transport.hpp"

namespace colorlab::bringup {

using nlohmann::json;

json identify_relay(const std::string& where, Recording* recording) {
  std::unique_ptr<drivers::HidTransport> transport;
  if (where.rfind("unix:", 0) == 0) {
    transport = std::make_unique<drivers::SocketHidTransport>(where.substr(5));
  } else {
    transport = std::make_unique<drivers::HidapiTransport>(where);
  }
  if (recording) transport = std::make_unique<RecordingHidTransport>(std::move(transport), *recording);
  return identify_relay(std::move(transport), where);
}

json identify_relay(std::unique_ptr<drivers::HidTransport> transport, const std::string& where) {
  const auto start = std::chrono::steady_clock::now();
  json j{{"where", where}};
  auto* t = transport.get();
  try {
    boost::asio::io_context io;
    drivers::HidRelayOptions o;
    o.reconnect.max_attempts = 0;
    drivers::HidRelay relay(io.get_executor(), std::move(transport), o);
    auto fut = boost::asio::co_spawn(io, relay.connect(), boost::asio::use_future);
    io.run();
    fut.get();
    auto id = relay.identity();
    const auto info = t->info();
    j["hid"] = {
        {"product", info.product},
        {"manufacturer", info.manufacturer},
        {"serial", info.serial},
        {"vendor_id", info.vendor_id},
        {"product_id", info.product_id},
    };
    j["verdict"] = "identified";
    j["model"] = id.model;
    j["board_id"] = id.serial;
    j["relays"] = relay.relay_count();
    json on = json::array();
    for (int r = 1; r <= relay.relay_count(); ++r) {
      if (relay.state_mask() & (1u << (r - 1))) on.push_back(r);
    }
    j["relays_on"] = on;
    j["message"] = "a dcttech relay board answered its state report: board id '" + id.serial + "', " +
                   std::to_string(relay.relay_count()) + " relays, " + std::to_string(on.size()) + " on";
    j["calibration"] = {{"applies", false}, {"detail", "a relay board has no calibration"}};
    relay.disconnect();
  } catch (const Error& e) {
    j["verdict"] = "failed";
    j["message"] = e.info().message;
    if (!e.hint().empty()) j["hint"] = e.hint();
  }
  j["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return j;
}

}  // namespace colorlab::bringup
