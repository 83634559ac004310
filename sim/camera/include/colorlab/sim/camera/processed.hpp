#pragma once
// The camera's own processing, as the EOS 20D's JPEG/TIFF path does it for the camera-colour-space method
// (§7.1): bilinear demosaic, as-shot white balance, the camera's built-in (imperfect) colour matrix, and
// Adobe RGB (1998) encoding with gamma 563/256. Output as 8-bit or 16-bit TIFF (libtiff) and JPEG (libjpeg).
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "colorlab/sim/camera/camera_model.hpp"

namespace colorlab::sim::camera {

struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> rgb;  // interleaved R, G, B; Adobe RGB (1998) encoded, 0..65535
};

struct DevelopSettings {
  // Linear gain after black subtraction, relative to "white level → 1.0".
  double exposure = 1.0;
  // Camera-neutral of the light (R/G, 1, B/G); default: the camera's as-shot neutral for the scene.
  std::optional<std::array<double, 3>> neutral;
};

// Renders `frame` as the camera would. Throws Error(bad_parameter) for a frame that is not RGGB.
RgbImage develop(const RawFrame& frame, const CameraModel& camera, const DevelopSettings& settings = {});

// The camera's built-in matrix from white-balanced camera RGB to XYZ (D65), row-major: the inverse of its
// least-squares chart fit with a deliberate "pleasing" saturation boost, so it is close but not exact.
std::array<double, 9> builtin_camera_to_xyz(const CameraModel& camera);

// bits = 8 or 16. Temp file + rename. Throws Error(io_error) naming the path.
void write_tiff(const std::filesystem::path& path, const RgbImage& image, int bits);
// Baseline JPEG (8-bit, 4:4:4 at quality ≥ 90). Throws Error(unsupported) when built without libjpeg.
void write_jpeg(const std::filesystem::path& path, const RgbImage& image, int quality = 92);

}  // namespace colorlab::sim::camera
