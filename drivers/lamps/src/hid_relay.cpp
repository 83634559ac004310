#include "colorlab/drivers/hid_relay.hpp"

#include "colorlab/core/log.hpp"
#include "colorlab/wire/hid_relay_protocol.hpp"

namespace colorlab::drivers {

namespace asio = boost::asio;

HidRelay::HidRelay(asio::any_io_executor executor, std::unique_ptr<HidTransport> transport, HidRelayOptions options)
    : options_(std::move(options)), transport_(std::move(transport)), reconnector_(executor, options_.reconnect) {}

Identity HidRelay::identity() const {
  auto info = transport_->info();
  return Identity{"hidrelay", product_.empty() ? "dcttech USBRelay" : "dcttech " + product_, board_id_, "",
                  info.path, options_.simulated};
}

void HidRelay::fail(const Error& e) {
  last_problem_ = std::string(e.what()) + (e.hint().empty() ? "" : " (" + e.hint() + ")");
  state_ = e.cls() == ErrorClass::no_comms                                           ? InstrumentState::disconnected
           : e.cls() == ErrorClass::conflict || e.cls() == ErrorClass::bad_parameter ? state_
                                                                                     : InstrumentState::fault;
  throw e;
}

std::uint8_t HidRelay::read_mask() {
  auto s = wire::hidrelay::parse_state(transport_->get_feature_report(0, wire::hidrelay::kReportDataBytes));
  mask_ = s.mask;
  return mask_;
}

asio::awaitable<void> HidRelay::connect() {
  state_ = InstrumentState::initialising;
  try {
    transport_->open();
    auto info = transport_->info();
    relay_count_ = wire::hidrelay::relay_count_from_product(info.product);
    product_ = info.product;
    auto s = wire::hidrelay::parse_state(transport_->get_feature_report(0, wire::hidrelay::kReportDataBytes));
    if (!options_.expected_board_id.empty() && s.id != options_.expected_board_id) {
      throw Error(ErrorClass::protocol_error,
                  "relay board id is '" + s.id + "', configured '" + options_.expected_board_id + "'",
                  "another board is plugged in, or set expected_board_id to match");
    }
    for (const auto& name : options_.lamps.names()) {
      if (options_.lamps.output(name) > relay_count_) {
        throw Error(ErrorClass::bad_parameter, "lamp '" + name + "' is on relay " + std::to_string(options_.lamps.output(name)) +
                                                   " but " + product_ + " has " + std::to_string(relay_count_));
      }
    }
    board_id_ = s.id;
    mask_ = s.mask;
    state_ = InstrumentState::ready;
    last_problem_.clear();
  } catch (const Error& e) {
    transport_->close();
    fail(e);
  }
  co_return;
}

void HidRelay::disconnect() {
  transport_->close();
  state_ = InstrumentState::disconnected;
}

void HidRelay::switch_verified(int relay, bool on) {
  const std::uint8_t bit = static_cast<std::uint8_t>(1u << (relay - 1));
  for (int attempt = 1; attempt <= options_.switch_attempts; ++attempt) {
    transport_->send_feature_report(wire::hidrelay::switch_one(relay, on));
    if (((read_mask() & bit) != 0) == on) return;
    log::warning("hidrelay", options_.id + ": relay " + std::to_string(relay) + " did not switch " + (on ? "on" : "off") +
                                 " (attempt " + std::to_string(attempt) + ")");
  }
  throw Error(ErrorInfo{ErrorClass::hardware_fail,
                        options_.id + ": relay " + std::to_string(relay) + " is stuck " + (on ? "off" : "on") + " after " +
                            std::to_string(options_.switch_attempts) + " switch attempts (read-back mask " +
                            std::to_string(mask_) + ")",
                        "the relay contact may be welded or its coil dead: check the board before trusting this lamp",
                        "relay:" + std::to_string(relay),
                        {},
                        false,
                        {}});
}

void HidRelay::apply(const std::vector<int>& relays_on) {
  std::uint8_t wanted = 0;
  for (int r : relays_on) wanted |= static_cast<std::uint8_t>(1u << (r - 1));
  read_mask();
  // Break before make: every unwanted lamp is off before the next one is lit, so two never overlap.
  for (const auto& name : options_.lamps.names()) {
    int r = options_.lamps.output(name);
    std::uint8_t bit = static_cast<std::uint8_t>(1u << (r - 1));
    if ((mask_ & bit) && !(wanted & bit)) switch_verified(r, false);
  }
  for (int r : relays_on) {
    std::uint8_t bit = static_cast<std::uint8_t>(1u << (r - 1));
    if (!(mask_ & bit)) switch_verified(r, true);
  }
}

asio::awaitable<void> HidRelay::set_lamps(std::vector<std::string> on) {
  std::vector<int> relays;
  try {
    relays = options_.lamps.outputs_for(on);
  } catch (const Error& e) {
    fail(e);
  }
  if (state_ == InstrumentState::disconnected) co_await connect();
  state_ = InstrumentState::busy;
  try {
    bool unplugged = false;
    try {
      apply(relays);
    } catch (const Error& e) {
      if (e.cls() != ErrorClass::no_comms) throw;
      log::warning("hidrelay", options_.id + ": " + e.what() + "; reconnecting");
      unplugged = true;
    }
    if (unplugged) {
      co_await reconnector_.reconnect(*this);
      state_ = InstrumentState::busy;
      apply(relays);
    }
    state_ = InstrumentState::ready;
    last_problem_.clear();
  } catch (const Error& e) {
    fail(e);
  }
}

std::vector<std::string> HidRelay::lamps_on() const {
  std::vector<std::string> out;
  for (const auto& name : options_.lamps.names()) {
    if (mask_ & (1u << (options_.lamps.output(name) - 1))) out.push_back(name);
  }
  return out;
}

}  // namespace colorlab::drivers
