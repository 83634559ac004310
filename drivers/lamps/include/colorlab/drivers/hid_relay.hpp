#pragma once
// Cabinet lamps switched by a dcttech USB HID relay board. Every switch is verified by reading the
// board's state back; a relay that does not follow is reported as stuck (hardware_fail) after
// bounded retries, and an unplugged board goes through the shared reconnect state machine.
// HID feature reports are short control transfers (a few ms), so they run inline on the executor.
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>

#include "colorlab/wire/hid_transport.hpp"
#include "colorlab/drivers/lab_capabilities.hpp"
#include "colorlab/drivers/lamp_map.hpp"
#include "colorlab/drivers/reconnect.hpp"

namespace colorlab::drivers {

struct HidRelayOptions {
  std::string id = "relay";
  std::string expected_board_id;  // 5-char board id to insist on; empty = any
  LampMap lamps;
  bool simulated = false;
  int switch_attempts = 3;  // per relay, before declaring it stuck
  ReconnectPolicy reconnect;
};

class HidRelay final : public LampController {
 public:
  HidRelay(boost::asio::any_io_executor executor, std::unique_ptr<HidTransport> transport, HidRelayOptions options);

  const std::string& id() const override { return options_.id; }
  Identity identity() const override;
  InstrumentState state() const override { return state_; }
  std::vector<Capability> capabilities() const override { return {Capability::lamp_switching}; }
  std::string last_problem() const override { return last_problem_; }

  boost::asio::awaitable<void> connect() override;
  void disconnect() override;

  std::vector<std::string> lamp_names() const override { return options_.lamps.names(); }
  boost::asio::awaitable<void> set_lamps(std::vector<std::string> on) override;
  std::vector<std::string> lamps_on() const override;

  int relay_count() const { return relay_count_; }
  std::uint8_t state_mask() const { return mask_; }
  const Reconnector& reconnector() const { return reconnector_; }

 private:
  void apply(const std::vector<int>& relays_on);
  void switch_verified(int relay, bool on);
  std::uint8_t read_mask();
  [[noreturn]] void fail(const Error& e);

  HidRelayOptions options_;
  std::unique_ptr<HidTransport> transport_;
  Reconnector reconnector_;
  InstrumentState state_ = InstrumentState::disconnected;
  std::string last_problem_;
  std::string board_id_;
  std::string product_;
  int relay_count_ = 0;
  std::uint8_t mask_ = 0;
};

}  // namespace colorlab::drivers
