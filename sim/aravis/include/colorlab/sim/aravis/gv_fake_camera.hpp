#pragma once
// The simulated lab's GenICam camera: Aravis's GigE Vision fake camera served on loopback, so the
// Aravis driver runs its real GVCP/GVSP code path. Aravis's built-in GenICam description offers
// only 8-bit Bayer and Mono16; we derive ours from it at run time (nothing of Aravis is copied
// into the repository) by adding BayerRG12 and BayerRG16, and the sensor is enlarged to the
// 20D's 3504 x 2336 through the fake's sensor-size registers. Pixels come from a fill function
// (the scene renderer), called on Aravis's camera thread for each frame with the current ROI,
// exposure and gain.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace colorlab::sim::aravis {

struct FillRequest {
  int x = 0;  // region of interest on the sensor
  int y = 0;
  int width = 0;
  int height = 0;
  std::string_view pixel_format;  // "BayerRG12", "BayerRG16", "Mono16"
  double exposure_us = 0;
  double gain = 0;  // GainRaw, 0..10
  std::uint64_t frame_id = 0;
};

// Writes width*height samples, row-major, into `out`. Called only for 16-bit pixel formats.
using FillFunction = std::function<void(const FillRequest&, std::span<std::uint16_t> out)>;

struct GvFakeOptions {
  std::string address = "127.0.0.1";
  std::string serial = "CLGV0001";  // at most 15 characters (GigE Vision bootstrap field)
  int sensor_width = 3504;
  int sensor_height = 2336;
  FillFunction fill;  // empty: a deterministic test pattern (see test_pattern_value)
};

class GvFakeCamera {
 public:
  // Throws Error(conflict) if the GVCP port on `address` is taken (another fake still running).
  explicit GvFakeCamera(GvFakeOptions options);
  ~GvFakeCamera();
  GvFakeCamera(const GvFakeCamera&) = delete;
  GvFakeCamera& operator=(const GvFakeCamera&) = delete;

  const std::string& address() const;
  const std::string& serial() const;  // of the body currently plugged in
  std::uint64_t frames_filled() const;

  // Fault injection "capture timeout": the camera stops acquiring as if its firmware hung, so
  // every frame request times out until the client starts a new acquisition.
  void stall();
  // Fault injection "disconnect": the camera leaves the network (its GVCP/GVSP sockets close) but
  // the address stays reserved for it, so no other fake answers a client that is still retrying.
  void unplug();
  // Back on the network, optionally as a different body (another serial) to test identity checks.
  void plug_in(std::optional<std::string> serial = std::nullopt);
  bool plugged_in() const;

  // Aravis's built-in fake GenICam XML with BayerRG12/BayerRG16 added to PixelFormat.
  static std::string genicam_xml();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The default fill, exact and cheap for format and ROI tests: 1000 * (CFA cell 0..3 of RGGB at
// the sensor position) + (x + 3 * y) % 997, always within 12 bits.
std::uint16_t test_pattern_value(int sensor_x, int sensor_y);

}  // namespace colorlab::sim::aravis
