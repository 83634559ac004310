#pragma once
// The lab configuration's [[lens]] tables (docs/verify.md "The lens calibration"): read by colorlabd's
// configuration and by `colorlab scene --lab FILE` / `colorlab lens list --lab FILE`.
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "colorlab/verify/lens_calibration.hpp"

namespace colorlab::verify {

// Keys: camera, lens, focal_length_mm, focus, width_px, height_px, fx, fy, cx, cy, k1, k2, sigma = {fx, fy, cx,
// cy, k1, k2}, rms_px, photographs, points, source, date. Unknown keys, a missing camera, lens or intrinsic, sizes
// ≤ 0, a principal point outside the frame and two calibrations of one name are refused with
// `file:line: lens: what` (Error bad_parameter).
std::vector<LensCalibration> lenses_from_toml(const toml::array& tables, const std::string& file);

}  // namespace colorlab::verify
