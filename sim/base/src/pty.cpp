#include "colorlab/sim/pty.hpp"

#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "colorlab/core/error.hpp"

namespace colorlab::sim {

namespace {

[[noreturn]] void throw_errno(const std::string& what) {
  throw Error(ErrorClass::io_error, what + ": " + std::strerror(errno), "the simulator needs /dev/ptmx (devpts)");
}

unsigned speed_to_baud(speed_t s) {
  switch (s) {
    case B110: return 110;
    case B300: return 300;
    case B600: return 600;
    case B1200: return 1200;
    case B2400: return 2400;
    case B4800: return 4800;
    case B9600: return 9600;
    case B19200: return 19200;
    case B38400: return 38400;
    case B57600: return 57600;
    case B115200: return 115200;
    case B230400: return 230400;
    case B460800: return 460800;
    case B921600: return 921600;
    default: return 0;
  }
}

}  // namespace

Pty::Pty() {
  master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master_ < 0) throw_errno("posix_openpt");
  if (::grantpt(master_) != 0 || ::unlockpt(master_) != 0) throw_errno("grantpt/unlockpt");
  char name[128];
  if (::ptsname_r(master_, name, sizeof name) != 0) throw_errno("ptsname");
  slave_path_ = name;
  slave_ = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (slave_ < 0) throw_errno("open " + slave_path_);
  // Raw from the start: no echo or line editing before a client has configured the port.
  termios t{};
  ::tcgetattr(slave_, &t);
  ::cfmakeraw(&t);
  ::cfsetispeed(&t, B9600);
  ::cfsetospeed(&t, B9600);
  ::tcsetattr(slave_, TCSANOW, &t);
}

Pty::~Pty() {
  if (master_ >= 0) ::close(master_);
  if (slave_ >= 0) ::close(slave_);
}

int Pty::release_master() {
  int fd = master_;
  master_ = -1;
  return fd;
}

LineSettings Pty::client_settings() const {
  termios t{};
  LineSettings s;
  if (::tcgetattr(slave_, &t) != 0) return s;
  s.baud = speed_to_baud(::cfgetospeed(&t));
  switch (t.c_cflag & CSIZE) {
    case CS5: s.data_bits = 5; break;
    case CS6: s.data_bits = 6; break;
    case CS7: s.data_bits = 7; break;
    default: s.data_bits = 8; break;
  }
  s.parity = (t.c_cflag & PARENB) != 0;
  s.stop_bits = (t.c_cflag & CSTOPB) ? 2 : 1;
  s.rts_cts = (t.c_cflag & CRTSCTS) != 0;
  return s;
}

}  // namespace colorlab::sim
