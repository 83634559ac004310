#pragma once
// A pseudo-terminal pair. The simulator keeps the master and also holds the slave open, so the
// master never sees EIO between client connections (a client may close and reopen the port).
#include <termios.h>

#include <string>

namespace colorlab::sim {

struct LineSettings {
  unsigned baud = 0;
  unsigned data_bits = 8;
  bool parity = false;
  unsigned stop_bits = 1;
  bool rts_cts = false;
  unsigned bits_per_byte() const { return 1 + data_bits + (parity ? 1 : 0) + stop_bits; }
};

class Pty {
 public:
  Pty();
  ~Pty();
  Pty(const Pty&) = delete;
  Pty& operator=(const Pty&) = delete;

  int master_fd() const { return master_; }
  // Hands the master to its new owner (an Asio descriptor); the Pty no longer closes it.
  int release_master();
  const std::string& slave_path() const { return slave_path_; }
  // What the client configured on its end (speed, stop bits, RTS/CTS).
  LineSettings client_settings() const;

 private:
  int master_ = -1;
  int slave_ = -1;
  std::string slave_path_;
};

}  // namespace colorlab::sim
