#pragma once
// The simulated lab's tethered DSLR (colorlab-sim's `simdslr`, a Canon EOS 20D-like body) reached
// over its Unix socket with the tethered-camera protocol of docs/simulator.md. The camera writes
// its files (DNG, and the JPEG / TIFFs the image format asks for) into its capture directory and
// names them in the capture answer; this driver reads the raw's bytes and hands them to the same
// CapturedFrame -> LibRaw -> FramePipeline path a real DSLR's CR2 takes.
//
// The protocol is implemented here from the document, independently of the simulator's side, so a
// misreading of the document shows up as a failing test rather than as two halves agreeing on a bug.
// Every request carries an id and every wait a deadline: a capture the camera never answers is
// Error(timeout), and its answer arriving later is recognised by its id and dropped.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "colorlab/drivers/camera/camera.hpp"

namespace colorlab::drivers {
class UnixLineClient;
}

namespace colorlab::drivers::camera {

struct SimDslrOptions {
  std::string socket_path;  // required: the announcement's "port"
  // Downloaded files are copied here and deleted in the camera (as from a card); empty: they stay
  // in the camera's capture directory and saved_files name them there.
  std::filesystem::path keep_dir;
  std::chrono::milliseconds request_timeout{5000};  // identify, configure, delete
  // A capture may take its shutter time plus this (release, card write, transfer) before it is
  // declared lost. The simulator's times shrink by its time scale; this deadline does not.
  std::chrono::milliseconds capture_timeout{30000};
};

class SimDslrCamera final : public Camera {
 public:
  explicit SimDslrCamera(SimDslrOptions options);
  ~SimDslrCamera() override;

 protected:
  Connected do_connect() override;
  void do_disconnect() noexcept override;
  void do_configure(const CameraSettings& settings) override;
  CapturedFrame do_capture_frame(std::size_t index) override;

 private:
  // Sends {"id":n, ...request} and returns the answer with that id; throws the typed error of an
  // {"ok":false} answer, of a malformed line, of a lost connection or of the deadline.
  nlohmann::json request(nlohmann::json request, std::chrono::milliseconds timeout);

  SimDslrOptions options_;
  std::unique_ptr<UnixLineClient> link_;
  std::uint64_t next_id_ = 1;
  std::vector<std::pair<double, std::string>> shutter_labels_;  // seconds -> the camera's label
};

}  // namespace colorlab::drivers::camera
