#pragma once
// `--lens fx,fy,cx,cy[,k1,k2]` (OpenCV's model in pixels of the photograph, as `colorlab analyze locate-chart --lens`
// takes it), shared by `colorlab scene` and `colorlab verify`.
#include <optional>
#include <string>

#include "colorlab/verify/camera_pose.hpp"

namespace colorlab::cli {

// Empty text: nullopt. Error(bad_parameter) for anything but 4 or 6 numbers.
std::optional<verify::CameraIntrinsics> parse_lens(const std::string& text);

}  // namespace colorlab::cli
