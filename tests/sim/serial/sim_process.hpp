#pragma once
// Test helpers: run colorlab-sim as a child process with a TOML config, and talk to its ptys as a
// serial client would (termios speed and flow control on our end, reads with a deadline).
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/sim/control_channel.hpp"

namespace colorlab::test {

class SimProcess {
 public:
  explicit SimProcess(const std::string& toml, std::uint64_t seed = 7) {
    dir_ = std::filesystem::temp_directory_path() /
           ("colorlab-simserial-" + std::to_string(::getpid()) + "-" + std::to_string(counter()++));
    std::filesystem::create_directories(dir_);
    // These tests need no camera; leaving the GigE Vision fake off keeps 127.0.0.1 free for the tests that do.
    std::ofstream(dir_ / "lab.toml") << toml << (toml.find("[genicam]") == std::string::npos ? "\n[genicam]\nenabled = false\n" : "");
    int out[2];
    if (::pipe(out) != 0) throw std::runtime_error("pipe");
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], 1);
      ::close(out[0]);
      ::close(out[1]);
      std::string bin = std::string(COLORLAB_BIN_DIR) + "/colorlab-sim";
      std::string cfg = (dir_ / "lab.toml").string();
      std::string sock = (dir_ / "control.sock").string();
      std::string seed_s = std::to_string(seed);
      ::execl(bin.c_str(), bin.c_str(), "--config", cfg.c_str(), "--control", sock.c_str(), "--seed", seed_s.c_str(),
              static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(out[1]);
    std::string line;
    char c;
    while (::read(out[0], &c, 1) == 1 && c != '\n') line += c;
    ::close(out[0]);
    if (line.empty()) throw std::runtime_error("colorlab-sim printed no announcement");
    announcement_ = nlohmann::json::parse(line);
  }
  ~SimProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      int st = 0;
      ::waitpid(pid_, &st, 0);
    }
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  SimProcess(const SimProcess&) = delete;
  SimProcess& operator=(const SimProcess&) = delete;

  const nlohmann::json& announcement() const { return announcement_; }
  std::string port(const std::string& id) const {
    for (const auto& i : announcement_["instruments"]) {
      if (i["id"] == id) return i["port"];
    }
    throw std::runtime_error("no instrument " + id);
  }
  nlohmann::json control(const nlohmann::json& cmd) const {
    return sim::send_control_command(announcement_["control"].get<std::string>(), cmd);
  }
  const std::filesystem::path& dir() const { return dir_; }

 private:
  static int& counter() {
    static int n = 0;
    return n;
  }
  std::filesystem::path dir_;
  pid_t pid_ = -1;
  nlohmann::json announcement_;
};

class SerialClient {
 public:
  SerialClient(const std::string& path, unsigned baud, bool rts_cts = false) {
    fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (fd_ < 0) throw std::runtime_error("open " + path);
    set_speed(baud, rts_cts);
  }
  ~SerialClient() {
    if (fd_ >= 0) ::close(fd_);
  }
  SerialClient(const SerialClient&) = delete;
  SerialClient& operator=(const SerialClient&) = delete;

  void set_speed(unsigned baud, bool rts_cts = false) {
    termios t{};
    ::tcgetattr(fd_, &t);
    ::cfmakeraw(&t);
    speed_t s = baud == 4800 ? B4800 : baud == 9600 ? B9600
                                   : baud == 19200  ? B19200
                                   : baud == 57600  ? B57600
                                   : baud == 115200 ? B115200
                                   : baud == 2400   ? B2400
                                                    : B38400;
    ::cfsetispeed(&t, s);
    ::cfsetospeed(&t, s);
    if (rts_cts) t.c_cflag |= CRTSCTS;
    else t.c_cflag &= ~CRTSCTS;
    ::tcsetattr(fd_, TCSANOW, &t);
  }
  void write(const std::string& bytes) {
    std::size_t done = 0;
    while (done < bytes.size()) {
      ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
      if (n > 0) done += static_cast<std::size_t>(n);
      else ::usleep(1000);
    }
  }
  // Reads until `terminator` is seen or the deadline passes; returns what arrived (maybe partial).
  std::string read_until(const std::string& terminator, double timeout_s) {
    std::string got;
    auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (got.size() < terminator.size() || got.compare(got.size() - terminator.size(), terminator.size(), terminator) != 0) {
      auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
      if (left <= 0) break;
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left)) <= 0) continue;
      char buf[4096];
      ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n > 0) got.append(buf, static_cast<std::size_t>(n));
    }
    return got;
  }
  // Reads exactly n bytes or until the deadline.
  std::string read_n(std::size_t n, double timeout_s) {
    std::string got;
    auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (got.size() < n) {
      auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
      if (left <= 0) break;
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left)) <= 0) continue;
      char buf[4096];
      ssize_t r = ::read(fd_, buf, std::min(sizeof buf, n - got.size()));
      if (r > 0) got.append(buf, static_cast<std::size_t>(r));
    }
    return got;
  }
  std::string transact(const std::string& request, double timeout_s = 2.0) {
    write(request);
    return read_until("\r\n", timeout_s);
  }

 private:
  int fd_ = -1;
};

}  // namespace colorlab::test
