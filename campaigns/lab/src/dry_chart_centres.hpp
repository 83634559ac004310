#pragma once
// The dry run's photograph of a chart the operator placed (lens-calibration's place_chart): each patch's centre seen
// through an ideal pinhole camera, so lab.analysis.calibrate_lens runs in a dry run as it will on the night.
#include <string>

#include <nlohmann/json.hpp>

namespace colorlab::campaigns::detail {

// The dry photograph's size, and observed_px ([{id, x, y}, …], every patch) of the `chart` ("sg", "cc24") at `placement` — the last
// place_chart request's details {tilt_deg, swing_deg, rotation_deg, fill, shift_x, shift_y}; missing keys: square
// to the camera, centred, filling 0.8 of the frame's height.
constexpr int kDryPhotoWidth = 3504, kDryPhotoHeight = 2336;
nlohmann::json dry_chart_centres(const nlohmann::json& placement, const std::string& chart);

}  // namespace colorlab::campaigns::detail
