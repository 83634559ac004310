#pragma once
// A camera as one of the daemon's instruments: the generic identity/state/capability view the API
// lists, plus the Camera itself for campaigns that capture. connect() runs on the camera's own
// thread and completes on the caller's executor.
#include <memory>
#include <string>

#include "colorlab/drivers/camera/camera.hpp"
#include "colorlab/drivers/instrument.hpp"

namespace colorlab::drivers::camera {

class CameraInstrument final : public Instrument {
 public:
  CameraInstrument(std::string id, std::string port, bool simulated, std::unique_ptr<Camera> camera);

  const std::string& id() const override { return id_; }
  Identity identity() const override;
  InstrumentState state() const override;
  std::vector<Capability> capabilities() const override { return {Capability::camera}; }
  std::string last_problem() const override { return last_problem_; }

  boost::asio::awaitable<void> connect() override;
  void disconnect() override;

  Camera& camera() { return *camera_; }

 private:
  std::string id_;
  std::string port_;
  bool simulated_;
  std::unique_ptr<Camera> camera_;
  std::string last_problem_;
};

}  // namespace colorlab::drivers::camera
