#pragma once
// The simulator's control channel: a Unix socket speaking JSON lines (one command per line, one
// answer per line), so tests and demos can read ground truth and inject faults at run time.
// Try it: echo '{"cmd":"truth"}' | socat - UNIX-CONNECT:/path/from/the/announcement
#include <filesystem>
#include <functional>
#include <memory>

#include <boost/asio/io_context.hpp>
#include <nlohmann/json.hpp>

namespace colorlab::sim {

class ControlChannel {
 public:
  using Handler = std::function<nlohmann::json(const nlohmann::json&)>;
  ControlChannel(boost::asio::io_context& io, std::filesystem::path path, Handler handler);
  ~ControlChannel();
  const std::filesystem::path& path() const;

  struct Impl;  // public so the connection coroutines can share it

 private:
  std::shared_ptr<Impl> impl_;
};

// Sends one command to a running simulator and returns its answer (for tests and the CLI).
nlohmann::json send_control_command(const std::filesystem::path& socket, const nlohmann::json& command);

}  // namespace colorlab::sim
