#include "colorlab/drivers/camera/camera_settings.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::drivers::camera {

std::string_view to_string(ImageFormat f) {
  switch (f) {
    case ImageFormat::raw: return "raw";
    case ImageFormat::jpeg: return "jpeg";
    case ImageFormat::raw_and_jpeg: return "raw+jpeg";
    case ImageFormat::raw_jpeg_tiff: return "raw+jpeg+tiff";
  }
  return "?";
}

ImageFormat image_format_from_string(std::string_view name) {
  for (auto f : {ImageFormat::raw, ImageFormat::jpeg, ImageFormat::raw_and_jpeg, ImageFormat::raw_jpeg_tiff}) {
    if (to_string(f) == name) return f;
  }
  throw Error(ErrorClass::bad_parameter, "unknown image format '" + std::string(name) + "'",
              "use one of raw, jpeg, raw+jpeg, raw+jpeg+tiff");
}

std::string_view to_string(PixelFormat f) {
  switch (f) {
    case PixelFormat::bayer_rg12: return "BayerRG12";
    case PixelFormat::bayer_rg16: return "BayerRG16";
    case PixelFormat::mono16: return "Mono16";
  }
  return "?";
}

PixelFormat pixel_format_from_string(std::string_view name) {
  for (auto f : {PixelFormat::bayer_rg12, PixelFormat::bayer_rg16, PixelFormat::mono16}) {
    if (to_string(f) == name) return f;
  }
  throw Error(ErrorClass::bad_parameter, "unknown pixel format '" + std::string(name) + "'",
              "use one of BayerRG12, BayerRG16, Mono16");
}

void CameraSettings::merge(const CameraSettings& n) {
  if (n.iso) iso = n.iso;
  if (n.shutter_s) shutter_s = n.shutter_s;
  if (n.aperture_f) aperture_f = n.aperture_f;
  if (n.image_format) image_format = n.image_format;
  if (n.exposure_us) exposure_us = n.exposure_us;
  if (n.gain) gain = n.gain;
  if (n.pixel_format) pixel_format = n.pixel_format;
}

std::optional<std::size_t> match_choice(const std::vector<double>& choices, double value) {
  for (std::size_t i = 0; i < choices.size(); ++i) {
    if (std::abs(choices[i] - value) <= 0.01 * std::abs(choices[i])) return i;
  }
  return std::nullopt;
}

namespace {

std::string join(const std::vector<double>& v) {
  std::string s;
  for (double d : v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s%g", s.empty() ? "" : ", ", d);
    s += buf;
  }
  return s;
}

[[noreturn]] void unsupported(std::string_view camera, std::string_view setting) {
  throw Error(ErrorClass::unsupported,
              std::string(camera) + " has no setting '" + std::string(setting) + "'",
              "check limits() before configuring; DSLRs take iso/shutter/aperture/image format, "
              "GenICam cameras exposure/gain/pixel format");
}

[[noreturn]] void out_of_limits(std::string_view camera, std::string_view setting, double value,
                                std::string allowed) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", value);
  throw Error(ErrorClass::bad_parameter,
              std::string(camera) + ": " + std::string(setting) + " " + buf + " is not available",
              "allowed: " + allowed);
}

void check_choice(std::string_view camera, std::string_view setting, const std::optional<double>& value,
                  const std::vector<double>& choices) {
  if (!value) return;
  if (choices.empty()) unsupported(camera, setting);
  if (!match_choice(choices, *value)) out_of_limits(camera, setting, *value, join(choices));
}

void check_range(std::string_view camera, std::string_view setting, const std::optional<double>& value,
                 const std::optional<Range>& range) {
  if (!value) return;
  if (!range) unsupported(camera, setting);
  if (!std::isfinite(*value) || !range->contains(*value)) {
    out_of_limits(camera, setting, *value, join({range->min, range->max}) + " (min, max)");
  }
}

}  // namespace

void validate(const CameraSettings& w, const CameraLimits& l, std::string_view camera) {
  std::vector<double> isos(l.iso.begin(), l.iso.end());
  check_choice(camera, "iso", w.iso ? std::optional<double>(*w.iso) : std::nullopt, isos);
  check_choice(camera, "shutter", w.shutter_s, l.shutter_s);
  check_choice(camera, "aperture", w.aperture_f, l.aperture_f);
  if (w.image_format) {
    if (l.image_formats.empty()) unsupported(camera, "image format");
    if (std::find(l.image_formats.begin(), l.image_formats.end(), *w.image_format) == l.image_formats.end()) {
      std::string allowed;
      for (auto f : l.image_formats) allowed += (allowed.empty() ? "" : ", ") + std::string(to_string(f));
      throw Error(ErrorClass::bad_parameter,
                  std::string(camera) + ": image format " + std::string(to_string(*w.image_format)) +
                      " is not available",
                  "allowed: " + allowed);
    }
  }
  check_range(camera, "exposure_us", w.exposure_us, l.exposure_us);
  check_range(camera, "gain", w.gain, l.gain);
  if (w.pixel_format) {
    if (l.pixel_formats.empty()) unsupported(camera, "pixel format");
    if (std::find(l.pixel_formats.begin(), l.pixel_formats.end(), *w.pixel_format) == l.pixel_formats.end()) {
      std::string allowed;
      for (auto f : l.pixel_formats) allowed += (allowed.empty() ? "" : ", ") + std::string(to_string(f));
      throw Error(ErrorClass::bad_parameter,
                  std::string(camera) + ": pixel format " + std::string(to_string(*w.pixel_format)) +
                      " is not offered",
                  "allowed: " + allowed);
    }
  }
}

std::optional<double> parse_shutter_label(std::string_view label) {
  std::string s(label);
  while (!s.empty() && (s.back() == '"' || s.back() == 's' || s.back() == ' ')) s.pop_back();
  if (s.empty()) return std::nullopt;
  double num = 0;
  double den = 0;
  char tail = 0;
  if (std::sscanf(s.c_str(), "%lf/%lf%c", &num, &den, &tail) == 2 && den > 0 && num > 0) return num / den;
  if (std::sscanf(s.c_str(), "%lf%c", &num, &tail) == 1 && num > 0) return num;
  return std::nullopt;  // "Bulb", "auto", ...
}

std::string format_shutter_label(double seconds) {
  char buf[32];
  if (seconds < 0.3) {
    std::snprintf(buf, sizeof buf, "1/%.0f", 1.0 / seconds);
  } else {
    std::snprintf(buf, sizeof buf, "%g", seconds);
  }
  return buf;
}

}  // namespace colorlab::drivers::camera
