#pragma once
// The camera as an imaging luminance meter (issue 11, floor-luminance): one averaged photograph of the empty cabinet
// floor, and the camera's signal at every floor spot asked for — the spot's green pixels within its disc, averaged over
// the first n frames for each n of `subsets` (1, 2, 4, … frames), each the robust value of the averaged pixels. The
// frames never leave the camera's decode thread; only the spots' values come back, small enough to journal.
//
// options: {frames = 8, corners = {{x, y} × 4} (fractions of the frame's width and height: the floor's front-left,
//           front-right, back-right, back-left corners in the photograph; default the simulated lab's floor view),
//           floor_mm = {1200, 600} (the floor's width and depth), pitch_mm = {60, 54} (the spot grid's),
//           spots = {{row, col}, …} (0-based, row 0 at the front), spot_mm = 20 (diameter sampled),
//           keep = {"preview"}}
// returns {instrument, frames, width, height, corners_px, spot_mm, subsets = {n…}, unit = "DN above black (green)",
//          spots = {{row, col, x_mm, y_mm, px = {x, y}, pixels, signal = {per subset}, stdev = {per subset}}, …},
//          blobs}
#include <boost/asio/awaitable.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/frame_keeper.hpp"

namespace colorlab::drivers::camera {
class CameraInstrument;
}

namespace colorlab::campaigns {

boost::asio::awaitable<nlohmann::json> photograph_floor(drivers::camera::CameraInstrument& camera,
                                                        const nlohmann::json& options, FrameKeeper* keeper = nullptr);

// What a dry run answers for it: the same spots and subsets, every spot at one signal (a flat floor, a flat lens).
nlohmann::json dry_floor_photograph(const nlohmann::json& options, const std::string& instrument);

// lab.analysis.floor_luminance(photograph, calibration, {degree = 2, subset = n}): the flat field fitted on the
// calibration readings ({{row, col, luminance}, …}, spots the photograph sampled) and every spot's luminance —
// {degree, frames, coefficients, centre_px, radius_px, spots = {{row, col, luminance, gain}}, calibration = {{row,
// col, luminance, fitted, residual_pct}}}. Error(script_error) for a calibration spot the photograph did not sample.
nlohmann::json floor_luminance(const nlohmann::json& photograph, const nlohmann::json& calibration, const nlohmann::json& options);

}  // namespace colorlab::campaigns
