#include "colorlab/drivers/camera/camera_instrument.hpp"

#include <boost/asio/use_awaitable.hpp>

#include "colorlab/drivers/camera/asio_camera.hpp"

namespace colorlab::drivers::camera {

CameraInstrument::CameraInstrument(std::string id, std::string port, bool simulated, std::unique_ptr<Camera> camera)
    : id_(std::move(id)), port_(std::move(port)), simulated_(simulated), camera_(std::move(camera)) {}

Identity CameraInstrument::identity() const {
  auto c = camera_->identity();
  std::string kind{to_string(c.kind)};
  std::string model = c.make.empty() ? c.model : c.make + " " + c.model;
  return Identity{kind, model.empty() ? "camera" : model, c.serial, "", c.port.empty() ? port_ : c.port, simulated_};
}

InstrumentState CameraInstrument::state() const {
  switch (camera_->state()) {
    case CameraState::disconnected: return InstrumentState::disconnected;
    case CameraState::initialising: return InstrumentState::initialising;
    case CameraState::ready: return InstrumentState::ready;
    case CameraState::busy: return InstrumentState::busy;
    case CameraState::fault: return InstrumentState::fault;
  }
  return InstrumentState::fault;
}

boost::asio::awaitable<void> CameraInstrument::connect() {
  std::optional<Error> error = co_await async_connect(*camera_, boost::asio::use_awaitable);
  if (error) {
    last_problem_ = error->info().message + (error->hint().empty() ? "" : " (" + error->hint() + ")");
    throw *error;
  }
  last_problem_.clear();
}

void CameraInstrument::disconnect() { camera_->disconnect().wait(); }

}  // namespace colorlab::drivers::camera
