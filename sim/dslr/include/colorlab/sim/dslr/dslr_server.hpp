#pragma once
// The simulated DSLR on its Unix socket: the tethered-camera protocol of docs/simulator.md, one
// client at a time (like a camera's single USB connection; a second gets "in_use"), answers paced
// in simulated time (release, shutter, transfer ÷ time scale), frames rendered on a worker thread
// so the lab's other instruments keep answering meanwhile.
//
// Faults (set through the control channel): a capture that is never answered, a capture answered
// "busy", a garbled answer line, and a camera that leaves (its connection closes and its socket
// disappears, so discovery sees it go) until told to come back or for a number of seconds.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <boost/asio/any_io_executor.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/sim/clock.hpp"
#include "colorlab/sim/dslr/dslr_body.hpp"

namespace colorlab::sim::dslr {

class DslrServer {
 public:
  DslrServer(boost::asio::any_io_executor executor, std::shared_ptr<DslrBody> body, std::filesystem::path socket_path,
             std::shared_ptr<const SimClock> clock);
  ~DslrServer();
  DslrServer(const DslrServer&) = delete;
  DslrServer& operator=(const DslrServer&) = delete;

  void start();  // throws Error(io_error) if the socket cannot be bound
  void stop();

  const std::filesystem::path& socket_path() const;
  DslrBody& body();

  // Keys: capture_timeout, busy, malformed_answer (true or a count of one-shot uses), disconnect
  // (true: gone until false), disconnect_s (gone for that many simulated seconds). Unmentioned
  // keys keep their values. Answers the fault set now. Throws Error(bad_parameter).
  nlohmann::json set_faults(const nlohmann::json& faults);
  nlohmann::json faults() const;

  // Serving statistics and the last shot, for the control channel's truth.
  nlohmann::json truth() const;
  // Ground truth of one shot ("IMG_0001.DNG"; nullopt: the last): per patch its pixel region and the
  // noiseless mean counts of R, G, B, the per-pixel noise the model injects there, the dust-covered
  // patches and the defective pixels. Throws Error(not_found) for an unknown or too old shot.
  nlohmann::json shot_truth(const std::optional<std::string>& file) const;

  struct Impl;  // public so the connection coroutines can share it

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace colorlab::sim::dslr
