#pragma once
// The whole simulated lab in one object: the scene, every simulated instrument on its pty, and
// the control commands (ground truth, fault injection, aiming, lamps) that tests and demos use.
// Runs on the caller's io_context; control() must be called on that context's thread.
#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/sim/lab_config.hpp"

namespace colorlab::sim {

class Scene;

class Lab {
 public:
  Lab(boost::asio::io_context& io, LabConfig config);
  ~Lab();

  // The one JSON line colorlab-sim prints: every endpoint with kind, model and port.
  nlohmann::json announcement() const;
  // One control command → its JSON answer; never throws (errors come back as {"ok":false,...}).
  nlohmann::json control(const nlohmann::json& command);

  Scene& scene();
  const LabConfig& config() const;

 private:
  void start_dslr();
  void start_relay();

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace colorlab::sim
