#pragma once
// GenICam machine-vision camera through Aravis (GigE Vision, USB3 Vision). One series is one
// acquisition: a small pool of buffers cycles between Aravis's stream thread and us, and each
// frame is requested by a software trigger, so the frame count is exact and no stale frame from
// a free-running camera ends up in an average. The stream socket buffer is fixed at 4 MB: with
// the automatic size the non-root UDP path drops packets (MISSING_PACKETS) at full frame.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "colorlab/drivers/camera/camera.hpp"

namespace colorlab::drivers::camera {

struct Region {
  int x = 0;
  int y = 0;
  int width = 0;
  int height = 0;
};

struct AravisOptions {
  std::string device_id;                // "127.0.0.1", "<vendor>-<serial>", ...; empty: first found
  std::optional<Region> region;         // sensor ROI; empty: full sensor
  std::optional<double> frame_rate_hz;  // upper bound on the trigger rate, if the camera has it
  unsigned n_buffers = 4;
  unsigned socket_buffer_bytes = 4'000'000;
  std::chrono::milliseconds frame_timeout{2000};
  unsigned max_retries_per_frame = 3;  // re-trigger after a timed-out or incomplete buffer
  bool software_trigger = true;
  // GenICam has no standard way to report the sensor's black offset in the pixel data, so it is
  // configured (from the camera's data sheet or a dark frame) and attached to every frame.
  std::uint16_t black_level = 0;
};

class AravisCamera final : public Camera {
 public:
  explicit AravisCamera(AravisOptions options);
  ~AravisCamera() override;

  // Buffers that failed during the last series (missing packets, timeouts), for diagnosis.
  std::uint64_t failed_buffers() const { return failed_buffers_.load(); }

 protected:
  Connected do_connect() override;
  void do_disconnect() noexcept override;
  void do_configure(const CameraSettings& settings) override;
  void do_begin_series(std::size_t n_frames) override;
  CapturedFrame do_capture_frame(std::size_t index) override;
  void do_end_series() noexcept override;

 private:
  struct Device;
  AravisOptions options_;
  std::unique_ptr<Device> device_;
  std::atomic<std::uint64_t> failed_buffers_{0};
};

}  // namespace colorlab::drivers::camera
