#pragma once
// An in-process simulated DSLR for driver tests and benches: renders each frame with a CameraModel
// the caller owns, writes it as a real DNG into a capture directory and hands the file's bytes to
// the same LibRaw decode stage a real DSLR's CR2 goes through. The simulated lab's DSLR, which the
// daemon uses, lives in colorlab-sim (sim/dslr) and is reached through SimDslrCamera.
//
// Image format RAW + JPEG adds the camera's own processed JPEG with the same basename, as the
// EOS 20D pairs IMG_nnnn.CR2 and IMG_nnnn.JPG (an 8-bit TIFF when built without libjpeg).
//
// Fault injection (one-shot, armed for a frame index of the next series): a capture that times
// out, a camera that answers "busy", and a camera that disappears (stays gone until connect()).
#include <chrono>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "colorlab/drivers/camera/camera.hpp"
#include "colorlab/sim/camera/camera_model.hpp"

namespace colorlab::drivers::camera {

struct SimulatedCameraOptions {
  std::shared_ptr<const sim::camera::CameraModel> model;  // required
  std::filesystem::path capture_dir;                      // required; created if missing
  std::string serial = "SIM20D0001";
  // Real time each capture takes on top of rendering and writing (shutter, transfer).
  std::chrono::milliseconds extra_capture_time{0};
  // How long a capture waits before reporting a timeout when that fault is armed.
  std::chrono::milliseconds timeout_after{50};
  bool keep_files = true;  // false: delete each DNG once it has been read back
  // Also write the camera's processed 16-bit TIFF next to each raw (the camera-colour-space
  // method's input); the JPEG partner is written when the image format is RAW + JPEG.
  bool write_tiff16 = false;
};

enum class CameraFault {
  capture_timeout,
  busy,
  disconnect
};

class SimulatedCamera final : public Camera {
 public:
  explicit SimulatedCamera(SimulatedCameraOptions options);
  ~SimulatedCamera() override;

  // Arms `fault` for the capture of frame `at_frame` (0-based) of the next series.
  void inject_fault(CameraFault fault, std::size_t at_frame);
  void clear_faults();

  // Frames rendered so far over the camera's life (each gets its own noise seed).
  std::uint64_t frames_rendered() const { return shots_.load(); }
  sim::camera::CameraSettings model_settings() const;  // current settings in the model's terms

 protected:
  Connected do_connect() override;
  void do_disconnect() noexcept override;
  void do_configure(const CameraSettings& settings) override;
  CapturedFrame do_capture_frame(std::size_t index) override;

 private:
  SimulatedCameraOptions options_;
  mutable std::mutex fault_mutex_;
  std::optional<std::pair<CameraFault, std::size_t>> fault_;
  bool unplugged_ = false;
  sim::camera::CameraSettings exposure_;
  ImageFormat format_ = ImageFormat::raw;
  std::atomic<std::uint64_t> shots_{0};
  std::array<double, 9> color_matrix_{};
  std::array<double, 3> neutral_{};
};

}  // namespace colorlab::drivers::camera
