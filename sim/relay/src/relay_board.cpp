#include "colorlab/sim/relay_board.hpp"

#include "colorlab/core/error.hpp"
#include "colorlab/wire/hid_relay_protocol.hpp"

namespace colorlab::sim {

struct RelayBoard::Shared {
  mutable std::mutex mutex;
  int relays;
  std::string id;
  std::string path;
  std::uint8_t mask = 0;
  RelayBoardFaults faults;
  int open_attempts_while_unplugged = 0;
  std::vector<std::vector<std::uint8_t>> sent;
  int reads = 0;
};

namespace {

Error unplugged_error(const std::string& path) {
  return Error(ErrorClass::no_comms, "relay board " + path + ": No such device (unplugged)", "reconnect the USB cable");
}

}  // namespace

class RelayBoardTransport final : public drivers::HidTransport {
 public:
  explicit RelayBoardTransport(std::shared_ptr<RelayBoard::Shared> s) : s_(std::move(s)) {}

  void open() override {
    std::lock_guard lock(s_->mutex);
    if (s_->faults.unplugged) {
      ++s_->open_attempts_while_unplugged;
      if (s_->faults.replug_after_opens < 0 || s_->open_attempts_while_unplugged < s_->faults.replug_after_opens) {
        throw unplugged_error(s_->path);
      }
      s_->faults.unplugged = false;
      s_->open_attempts_while_unplugged = 0;
      s_->mask = 0;  // a replugged board powers up with every relay off
    }
    open_ = true;
  }
  void close() override { open_ = false; }
  bool is_open() const override { return open_; }
  drivers::HidDeviceInfo info() const override {
    std::lock_guard lock(s_->mutex);
    return drivers::HidDeviceInfo{s_->path, 0x16C0, 0x05DF, "www.dcttech.com", "USBRelay" + std::to_string(s_->relays), ""};
  }

  void send_feature_report(const std::vector<std::uint8_t>& r) override {
    std::lock_guard lock(s_->mutex);
    check_link();
    s_->sent.push_back(r);
    if (r.size() != 9 || r[0] != 0) return;  // the firmware ignores reports it does not understand
    auto set = [&](std::uint8_t bits, bool on) {
      bits &= static_cast<std::uint8_t>((1u << s_->relays) - 1);
      bits &= static_cast<std::uint8_t>(~s_->faults.stuck_mask);
      s_->mask = on ? (s_->mask | bits) : (s_->mask & static_cast<std::uint8_t>(~bits));
    };
    switch (r[1]) {
      case 0xFF:
      case 0xFD:
        if (r[2] >= 1 && r[2] <= s_->relays) set(static_cast<std::uint8_t>(1u << (r[2] - 1)), r[1] == 0xFF);
        break;
      case 0xFE: set(0xFF, true); break;
      case 0xFC: set(0xFF, false); break;
      case 0xFA: s_->id.assign(r.begin() + 2, r.begin() + 7); break;
      default: break;
    }
  }

  std::vector<std::uint8_t> get_feature_report(std::uint8_t, std::size_t data_length) override {
    std::lock_guard lock(s_->mutex);
    check_link();
    ++s_->reads;
    auto d = wire::hidrelay::encode_state(wire::hidrelay::BoardState{s_->id, s_->mask});
    d.resize(data_length, 0);
    return d;
  }

 private:
  void check_link() const {
    if (s_->faults.unplugged) throw unplugged_error(s_->path);
    if (!open_) throw Error(ErrorClass::no_comms, "relay board " + s_->path + " is not open");
  }

  std::shared_ptr<RelayBoard::Shared> s_;
  bool open_ = false;
};

RelayBoard::RelayBoard(int relays, std::string id, std::string path) : shared_(std::make_shared<Shared>()) {
  shared_->relays = relays;
  shared_->id = std::move(id);
  shared_->path = std::move(path);
}

std::unique_ptr<drivers::HidTransport> RelayBoard::make_transport() { return std::make_unique<RelayBoardTransport>(shared_); }

void RelayBoard::set_faults(const RelayBoardFaults& f) {
  std::lock_guard lock(shared_->mutex);
  shared_->faults = f;
  shared_->open_attempts_while_unplugged = 0;
}
void RelayBoard::set_mask(std::uint8_t mask) {
  std::lock_guard lock(shared_->mutex);
  shared_->mask = static_cast<std::uint8_t>(mask & ((1u << shared_->relays) - 1));
}
RelayBoardFaults RelayBoard::faults() const {
  std::lock_guard lock(shared_->mutex);
  return shared_->faults;
}
std::uint8_t RelayBoard::mask() const {
  std::lock_guard lock(shared_->mutex);
  return shared_->mask;
}
std::string RelayBoard::board_id() const {
  std::lock_guard lock(shared_->mutex);
  return shared_->id;
}
std::vector<std::vector<std::uint8_t>> RelayBoard::sent_reports() const {
  std::lock_guard lock(shared_->mutex);
  return shared_->sent;
}
int RelayBoard::reads() const {
  std::lock_guard lock(shared_->mutex);
  return shared_->reads;
}

}  // namespace colorlab::sim
