// The client side of the simulated lab's tethered-camera protocol (drivers/camera sim_dslr_camera.cpp,
// docs/simulator.md "Tethered-camera protocol"): the input is what the camera answers, one JSON line
// per request, to connect (identify: make, model, serial, limits, settings) and a configure. Anything
// but a typed error is a finding — including the `internal` error the Camera base class makes of an
// exception a driver let escape. A capture is not fuzzed: its answer names files on this machine that
// the driver reads and hands to LibRaw.
#include "colorlab/drivers/camera/sim_dslr_camera.hpp"
#include "fuzz_support.hpp"
#include "line_peer.hpp"

namespace {

using colorlab::Error;
using colorlab::ErrorClass;
namespace cam = colorlab::drivers::camera;

void expect_typed(const char* what, std::future<void> done) {
  try {
    done.get();
  } catch (const Error& e) {
    if (e.cls() == ErrorClass::internal) {
      std::fprintf(stderr, "fuzz: %s: an untyped exception escaped the driver: %s\n", what, e.what());
      std::abort();
    }
  }
}

void one_input(const std::uint8_t* data, std::size_t size) {
  static colorlab::fuzz::LinePeer camera_socket("dslr.sock");
  camera_socket.set_answers(colorlab::fuzz::as_text(data, size));
  cam::SimDslrOptions options;
  options.socket_path = camera_socket.path();
  options.request_timeout = std::chrono::milliseconds(2000);
  cam::SimDslrCamera camera(options);
  expect_typed("connect", camera.connect());
  if (camera.state() != cam::CameraState::ready) return;
  cam::CameraSettings settings;
  const auto limits = camera.limits();
  if (!limits.iso.empty()) settings.iso = limits.iso.back();
  if (!limits.shutter_s.empty()) settings.shutter_s = limits.shutter_s.front();
  expect_typed("configure", camera.configure(settings));
}

}  // namespace

COLORLAB_FUZZ_TARGET("simdslr_socket", one_input)
