#pragma once
// A scripted dcttech USBRelay<N> board behind the HidTransport interface: it keeps an id and a
// state bitmask, obeys the ON/OFF/ALL/SET-ID feature reports like the real firmware, and can be
// told to fail the way boards do at night: a stuck relay, an unplugged cable, a replug.
// No virtual HID device can be created on the build machines, so this is the simulated side.
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "colorlab/wire/hid_transport.hpp"

namespace colorlab::sim {

struct RelayBoardFaults {
  std::uint8_t stuck_mask = 0;  // relays whose contacts no longer move (they keep their current state)
  bool unplugged = false;       // every transfer fails, opening fails
  int replug_after_opens = -1;  // while unplugged: the n-th open attempt finds it plugged in again
};

class RelayBoard {
 public:
  explicit RelayBoard(int relays = 8, std::string id = "CLRLB", std::string path = "/dev/hidraw-sim0");

  // A transport onto this board (the driver owns it; the board outlives it through shared state).
  std::unique_ptr<drivers::HidTransport> make_transport();

  void set_faults(const RelayBoardFaults& f);
  // The relays' state before any host talks to the board (lamps switched on by hand at start).
  void set_mask(std::uint8_t mask);
  RelayBoardFaults faults() const;
  std::uint8_t mask() const;
  std::string board_id() const;
  // Every report the host sent, in order (9 bytes each), for exact-exchange tests.
  std::vector<std::vector<std::uint8_t>> sent_reports() const;
  int reads() const;

 private:
  friend class RelayBoardTransport;
  struct Shared;
  std::shared_ptr<Shared> shared_;
};

}  // namespace colorlab::sim
