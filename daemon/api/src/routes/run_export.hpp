#pragma once
// A run's stored measurements as files (GET /v1/runs/{id}/export, `colorlab export`): CSV and JSON for any
// run, and an ArgyllCMS .ti3 for a run with patch readings. Pure: everything arrives as values, so the
// route decides how to page through the store and these functions only convert.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/store/store.hpp"

namespace colorlab::daemon::run_export {

enum class Format {
  ti3,
  csv,
  json
};

// "ti3", "csv" or "json"; throws Error(bad_parameter) naming the choices.
Format parse_format(std::string_view name);
// The format an Accept header asks for (text/csv, application/json, text/x-cgats …), in the header's
// order; nullopt when it names none of them (a wildcard names JSON).
std::optional<Format> format_for_accept(std::string_view accept);
std::string media_type(Format f);
std::string_view extension(Format f);
// "<campaign>-<run id>[-<part>].<ext>", reduced to characters safe in a Content-Disposition file name.
std::string file_name(const store::RunRecord& run, Format f, std::string_view part = {});

// One row per measurement: seq, step, instrument_id, simulated, quantity, value, unit, measured_at and data
// (the measurement's data as compact JSON). Numbers are written so that they read back exactly.
class CsvBody {
 public:
  CsvBody();
  void add(const store::MeasurementRecord& m);
  std::string take() { return std::move(text_); }

 private:
  std::string text_;
};

// {"run": <the run document>, "measurements": [<as GET /v1/runs/{id}/measurements gives them>]}.
class JsonBody {
 public:
  explicit JsonBody(const store::RunRecord& run);
  void add(const store::MeasurementRecord& m);
  std::string take();

 private:
  std::string text_;
  bool first_ = true;
};

// Patches read by a spectrophotometer (chart-read: quantity reflectance_spectrum, data {id, XYZ, Lab,
// first_nm, step_nm, values}). ArgyllCMS wants device values beside them, as chartread takes them from
// the chart's .ti2: each patch's own colour in sRGB stands there, as Argyll's reference charts carry a
// nominal RGB. DEVICE_CLASS "OUTPUT", XYZ and L*a*b* (D50), SPEC_* when every patch has a spectrum on one grid.
std::string reference_ti3(const store::RunRecord& run, const std::vector<store::MeasurementRecord>& patches);

// A camera's values of a chart (characterize-camera: quantity camera_rgb, data {id, format, rgb}) paired
// with the reference the run was fitted against (campaigns::chart_reference of its chart-read run):
// DEVICE_CLASS "INPUT" for colprof, the reference's XYZ, L*a*b* and spectra. RGB on 0–100: 8- and 16-bit
// codes by their full scale, raw counts above black by the largest count among the patches.
std::string camera_ti3(const store::RunRecord& run, const std::vector<store::MeasurementRecord>& patches,
                       const nlohmann::json& reference, const std::string& camera_format);

// The format a camera run's .ti3 takes by default: the one the run selected, else the first recorded.
std::string default_camera_format(const store::RunRecord& run, const store::MeasurementRecord& first_patch);

}  // namespace colorlab::daemon::run_export
