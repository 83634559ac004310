#pragma once
// The simulated lab's "hands": operator actions that colorlab-sim can carry out through its
// control channel, so a campaign on the simulated lab never waits for a person to aim the meter
// or put the Spectrolino on its tile. Actions it cannot do are left to a person (nullopt).
#include <filesystem>

#include <boost/asio/any_io_executor.hpp>

#include "colorlab/campaigns/operator_desk.hpp"

namespace colorlab::daemon {

class SimulatorHands final : public campaigns::OperatorHands {
 public:
  SimulatorHands(boost::asio::any_io_executor executor, std::filesystem::path control_socket);
  bool can_perform(const std::string& action) const override {
    return action == "aim_meter" || action == "load_chart" || action == "white_tile" || action == "aim_camera" ||
           action == "place_chart";
  }
  boost::asio::awaitable<std::optional<nlohmann::json>> perform(const std::string& action,
                                                                const nlohmann::json& details) override;
  // The chart back at its configured place after a place_chart pose, the cameras back at the chart after an
  // aim_camera at the floor; nothing for what leaves the lab at rest.
  boost::asio::awaitable<std::optional<nlohmann::json>> put_back(const std::string& action,
                                                                 const nlohmann::json& details) override;

 private:
  // One line of JSON out, one back; Error{no_comms|timeout|device_error} otherwise.
  boost::asio::awaitable<nlohmann::json> command(nlohmann::json cmd);

  boost::asio::any_io_executor executor_;
  std::filesystem::path socket_;
};

}  // namespace colorlab::daemon
