#pragma once
// A CFA DNG (DNG 1.4) written with libtiff, as camera-stack notes §3 verified LibRaw and dcraw decode exactly.
#include <array>
#include <filesystem>
#include <string>

#include "colorlab/sim/camera/raw_frame.hpp"

namespace colorlab::sim::camera {

struct DngMetadata {
  std::string make = "colorlab";
  std::string model = "Simulated EOS-20D";
  std::string unique_camera_model = "colorlab Simulated EOS-20D";
  std::array<double, 9> color_matrix1{1, 0, 0, 0, 1, 0, 0, 0, 1};  // XYZ → camera, D65 (CalibrationIlluminant1 = 21)
  std::array<double, 3> as_shot_neutral{1, 1, 1};
  std::string software = "colorlab-sim";
  std::string datetime;  // "YYYY:MM:DD HH:MM:SS"; empty = none (keeps files byte-reproducible)
};

// Writes `frame` to `path` via a temporary file in the same directory and an atomic rename.
// Throws Error(bad_parameter) for an inconsistent frame, Error(io_error) naming the path on I/O failure.
void write_dng(const std::filesystem::path& path, const RawFrame& frame, const DngMetadata& metadata);

}  // namespace colorlab::sim::camera
