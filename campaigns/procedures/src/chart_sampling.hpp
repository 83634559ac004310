#pragma once
// The chart photograph's pixels, averaged over the frames of one series per image format, and their
// chart location and patch values. Internal to chart_photograph.cpp; runs off the daemon's io thread.
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/analysis/chart_layout.hpp"
#include "colorlab/analysis/chart_locate.hpp"
#include "colorlab/analysis/chart_photo.hpp"

namespace colorlab::campaigns::detail {

// Averages are kept as 16-bit samples scaled by `scale` (2^(16 − significant bits)), so averaging N
// 12-bit raws or 8-bit JPEGs keeps its sub-count precision in a photo the locator reads; values are
// divided by `scale` again when reported.
struct AveragedPhoto {
  std::string format;  // "raw", "tiff16", "tiff8", "jpeg"
  int frames = 0;
  analysis::Photo photo;
  double scale = 1;
  int bits = 16;                            // significant bits before scaling
  double black_level = 0;                   // raw only, unscaled counts
  std::optional<analysis::CfaPattern> cfa;  // raw only
  std::vector<std::string> files;           // the frames' files, for the record
};

struct SamplingOptions {
  analysis::ChartType chart = analysis::ChartType::sg140;
  double sample_fraction = 0.6;
  double min_confidence = 0.6;
  // The chart's patch luminances from a reference read (chart-read's XYZ): lets the locator tell patches that
  // merely lack a luminance edge against the surround from a covered chart (chart_locate.hpp).
  std::optional<analysis::ChartReference> reference;
  // The operator's corners per format ("raw", "jpeg", …): the outer corners of the patch grid in that format's
  // pixels, the first patch's first, clockwise (chart_locate.hpp). Given after the locator refused a photograph.
  std::map<std::string, std::array<analysis::Point2, 4>> corners;
  // The locator's refusal (not_found, needs_operator, corners it cannot use) comes back as {format, refused = {…}}
  // instead of failing the call, so the frames are kept and the script can tell the operator which to look at.
  bool return_refusals = false;
  // Each detected patch's centroid as photographed (observed_px): a lens calibration's points (lens-calibration).
  bool centres = false;
};

// Sums of the camera's own processed files (JPEG, TIFF) of one format; throws Error(bad_data) when
// the frames differ in size or kind.
AveragedPhoto average_files(const std::string& format, const std::vector<std::filesystem::path>& files);
// The TIFFs of a series by sample type: "tiff8" and "tiff16".
std::map<std::string, AveragedPhoto> average_tiffs(const std::vector<std::filesystem::path>& files);

// Locates the chart (colorlab_chart_locate, as `colorlab analyze locate-chart`) and samples every
// patch: {format, frames, files, width, height, bits, black_subtracted, confidence, rotation_deg,
// corners, patches_detected, reprojection_rms_px, check, ids, values = [[r, g, b], …]}, with `centres` also
// observed_px = [{id, x, y}, …] of the detected patches (pixel centres at integers; a list without holes, which a
// Lua table could not carry).
// With corners for the format, the locator starts from them (from_corners). Throws the locator's typed Error, with
// the format named — or, with return_refusals, returns {format, frames, files, width, height, bits, chart,
// from_corners, refused = {error, message, hint}} for a refusal.
nlohmann::json locate_and_sample(const AveragedPhoto& averaged, const SamplingOptions& options);

}  // namespace colorlab::campaigns::detail
