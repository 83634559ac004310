#pragma once
// lab.analysis.calibrate_lens (the lens-calibration campaign): the chart photographed at several poses → the lab's
// lens calibration, by the code `colorlab lens calibrate` runs (verify::calibrate_lens_from_chart; docs/verify.md,
// "The lens calibration").
#include <nlohmann/json.hpp>

namespace colorlab::campaigns {

// photographs: [{chart, width, height, observed_px = [{id, x, y}, …]}, …] — lab.camera.photograph_chart's answer for
// one format, taken with centres = true (the detected patches' centroids as photographed); all of one size. options: {camera, lens (both required), focal_length_mm, focus, date, by (the
// source's first words)}. Returns the calibration as GET /v1/lab/lenses gives it (verify::lens_to_json) with `toml`,
// the [[lens]] table to paste into the lab configuration. Error(script_error) for malformed arguments (named);
// Error(bad_parameter) for fewer than 3 photographs or one with fewer than 20 detected patches, Error(bad_data) when
// the solution is not a lens (verify::calibrate_lens's).
nlohmann::json calibrate_lens(const nlohmann::json& photographs, const nlohmann::json& options);

}  // namespace colorlab::campaigns
