#pragma once
// The scripted relay board (relay_board.hpp) served on a Unix socket, so a separate process — the
// daemon's HidRelay through SocketHidTransport — can drive it: no virtual HID device can exist on
// these machines. Each connection is one opened hidraw node; each JSON line one HID operation
// (docs/simulator.md, "HID relay socket"), its feature report in hex, byte for byte.
// After every report the board's relay mask is compared with the one before, and each relay that
// moved is reported to `on_switch`, which lights or darkens the scene's lamp behind it.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>

#include <boost/asio/any_io_executor.hpp>

#include "colorlab/sim/relay_board.hpp"

namespace colorlab::sim {

class RelaySocketServer {
 public:
  using SwitchHandler = std::function<void(int relay, bool on)>;  // relay 1..8

  RelaySocketServer(boost::asio::any_io_executor executor, std::shared_ptr<RelayBoard> board, std::filesystem::path socket_path,
                    SwitchHandler on_switch);
  ~RelaySocketServer();
  RelaySocketServer(const RelaySocketServer&) = delete;
  RelaySocketServer& operator=(const RelaySocketServer&) = delete;

  void start();  // throws Error(io_error) if the socket cannot be bound
  void stop();
  const std::filesystem::path& socket_path() const;
  std::uint64_t requests() const;

  struct Impl;

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace colorlab::sim
