#pragma once
// The lens a photograph was taken through (the lab's lens calibration, docs/verify.md "The lens calibration"):
// OpenCV's pinhole with radial distortion k1, k2, in the photograph's pixels (pixel centres at integers). A
// rendering made with the exported camera is that pinhole without the distortion (Blender's camera does not
// distort), so a point photographed at p appears in the rendering at undistort(p) — the light half places the
// floor through it, and the report puts its maps back over the photograph through distort.
#include <array>
#include <string>

namespace colorlab::verify {

struct PhotographLens {
  double fx = 0, fy = 0, cx = 0, cy = 0, k1 = 0, k2 = 0;
  std::string name;  // where it came from, e.g. the stored calibration's name; said in the verification's output
};

// The pinhole position (same fx, fy, cx, cy) of a photographed position: the radial model inverted by Newton's
// method on the radius. Error(bad_parameter) for a lens without positive focal lengths; Error(bad_data) for a
// point beyond the radius where the model stops being one-to-one (it has no undistorted position there).
std::array<double, 2> undistort_px(const PhotographLens& lens, const std::array<double, 2>& photographed);
// The photographed position of a pinhole position (cv::projectPoints' radial model).
std::array<double, 2> distort_px(const PhotographLens& lens, const std::array<double, 2>& pinhole);

}  // namespace colorlab::verify
