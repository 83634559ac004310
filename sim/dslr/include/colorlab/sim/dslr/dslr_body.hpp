#pragma once
// The simulated DSLR's body, without any I/O of its own: what it is (identity and limits of an EOS
// 20D: ISO 100-1600, 1/8000-30 s in third stops, f/2.8-22), its settings, and a shot — the scene's
// current cabinet rendered by the camera model, written as a DNG plus the JPEG / TIFFs the image
// format asks for, with the ground truth of every patch for that very exposure.
// Requests and answers are the tethered-camera protocol's JSON objects (docs/simulator.md); a
// refusal is thrown as Refusal and becomes {"ok":false,"error":code}.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/sim/camera/camera_model.hpp"

namespace colorlab::sim::dslr {

// A request the camera refuses; `code` is one of the protocol's error codes.
struct Refusal {
  std::string code;
  std::string message;
};

struct DslrBodyConfig {
  std::string serial = "SIM20D0001";
  std::filesystem::path capture_dir;  // created if missing
  double release_s = 0.1;             // shutter lag before the exposure starts
  double transfer_s = 1.2;            // card write and USB transfer of the raw
  double sidecar_transfer_s = 0.4;    // each JPEG / TIFF beside it
};

struct ShotPlan {
  std::uint64_t shot = 0;  // 0-based over the body's life; noise seed and file number derive from it
  camera::CameraSettings exposure;
  std::string image_format;
};

struct ShotFile {
  std::string name;
  std::filesystem::path path;
  std::string type;  // raw, jpeg, tiff8, tiff16
  std::uint64_t bytes = 0;
};

struct ShotResult {
  ShotPlan plan;
  std::vector<ShotFile> files;
  std::vector<std::array<double, 3>> truth;  // CameraModel::ground_truth at the moment of the shot
};

class DslrBody {
 public:
  DslrBody(std::shared_ptr<const camera::CameraModel> model, DslrBodyConfig config);

  nlohmann::json identify() const;
  // Applies iso / shutter (a label) / aperture / image_format; all or nothing. Answers the settings.
  nlohmann::json configure(const nlohmann::json& request);
  nlohmann::json settings() const;
  // Removes files of earlier shots from the capture directory.
  nlohmann::json remove(const nlohmann::json& request);

  // The next shot at the current settings (on the serving thread) ...
  ShotPlan plan_shot();
  // ... how long it takes in simulated seconds (release, shutter, transfer of every file) ...
  double shot_seconds(const ShotPlan& plan) const;
  // ... and taking it: renders, writes the files. Thread-safe, for a worker thread. Throws Error.
  ShotResult take(const ShotPlan& plan) const;

  const camera::CameraModel& model() const { return *model_; }
  const DslrBodyConfig& config() const { return config_; }

 private:
  std::shared_ptr<const camera::CameraModel> model_;
  DslrBodyConfig config_;
  std::array<double, 9> color_matrix_{};
  mutable std::mutex mutex_;  // settings and the shot counter
  camera::CameraSettings exposure_;
  std::string image_format_ = "raw";
  std::uint64_t shots_ = 0;
};

}  // namespace colorlab::sim::dslr
