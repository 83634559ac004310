#pragma once
// Typed camera settings and the limits a camera reports for them. DSLRs offer discrete choices
// (ISO 100/200/..., shutter 1/60 s, f/8); GenICam cameras offer ranges (exposure in µs, gain).
// A setting a camera does not have is `unsupported`; a value outside its limits is `bad_parameter`.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace colorlab::drivers::camera {

// raw_jpeg_tiff: the raw plus the camera's own JPEG and its 8-bit and 16-bit TIFF from the same
// exposure (chapter 7 compares all four). Only the simulated DSLR offers it; on a bench the TIFFs
// come from the raw converter.
enum class ImageFormat {
  raw,
  jpeg,
  raw_and_jpeg,
  raw_jpeg_tiff
};
enum class PixelFormat {
  bayer_rg12,
  bayer_rg16,
  mono16
};

std::string_view to_string(ImageFormat f);
std::string_view to_string(PixelFormat f);
PixelFormat pixel_format_from_string(std::string_view genicam_name);  // throws bad_parameter
ImageFormat image_format_from_string(std::string_view name);          // "raw+jpeg"; throws bad_parameter

struct Range {
  double min = 0;
  double max = 0;
  bool contains(double v) const { return v >= min && v <= max; }
};

// Every field is optional: unset means "leave as is".
struct CameraSettings {
  // DSLR
  std::optional<int> iso;
  std::optional<double> shutter_s;   // exposure time in seconds, e.g. 1/60 = 0.016667
  std::optional<double> aperture_f;  // f-number, e.g. 8.0
  std::optional<ImageFormat> image_format;
  // GenICam
  std::optional<double> exposure_us;
  std::optional<double> gain;
  std::optional<PixelFormat> pixel_format;

  // Later fields override earlier ones where set.
  void merge(const CameraSettings& newer);
};

// What a camera accepts. An empty vector / nullopt means the camera has no such setting.
struct CameraLimits {
  std::vector<int> iso;
  std::vector<double> shutter_s;
  std::vector<double> aperture_f;
  std::vector<ImageFormat> image_formats;
  std::optional<Range> exposure_us;
  std::optional<Range> gain;
  std::vector<PixelFormat> pixel_formats;
};

// Throws Error(unsupported) for a setting the camera lacks and Error(bad_parameter) for a value
// outside its limits. Discrete choices match within 1 % so 1/60 s equals the camera's "1/60".
void validate(const CameraSettings& wanted, const CameraLimits& limits, std::string_view camera_name);

// Index of the choice within 1 % of `value`, or nullopt.
std::optional<std::size_t> match_choice(const std::vector<double>& choices, double value);

// "1/60" -> 1/60 s, "2.5" or "2.5\"" -> 2.5 s, "Bulb" -> nullopt; the strings DSLR firmwares use.
std::optional<double> parse_shutter_label(std::string_view label);
std::string format_shutter_label(double seconds);

}  // namespace colorlab::drivers::camera
