#pragma once
// A lab's lens calibration (issue 23, docs/verify.md "The lens calibration"): one camera body with one lens (at
// one focal length and focus setting where the lens has them), OpenCV's pinhole + radial model in pixels of the
// full photograph, with where it came from, when, and how well it is known. Obtained as a lab obtains one:
// OpenCV's calibrateCamera over photographs of the chart at several poses, the chart locator's detected patch
// centres as the calibration points. Kept in the lab configuration's [[lens]] tables (colorlabd.toml, or a lab
// file given to `colorlab scene --lab`), served at GET /v1/lab/lenses.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/verify/camera_pose.hpp"

namespace colorlab::verify {

struct LensCalibration {
  std::string camera;                     // the body, e.g. "Canon EOS 20D #1234"
  std::string lens;                       // e.g. "EF 50mm f/1.8 II"
  std::optional<double> focal_length_mm;  // the zoom's setting, for a zoom
  std::string focus;                      // the focus setting, where it was fixed ("" = not stated)
  int width_px = 0, height_px = 0;        // the photographs it holds for
  CameraIntrinsics intrinsics;            // fx, fy, cx, cy (px, pixel centres at integers), k1, k2
  CameraIntrinsics sigma;                 // one standard uncertainty of each parameter
  double rms_px = 0;                      // reprojection RMS of the calibration points
  int photographs = 0, points = 0;
  std::string source;        // how it was obtained
  std::string date;          // ISO 8601 day
  std::string name() const;  // "camera / lens[ @ f mm][, focus …]": how scene.json and the CLI name it
};

// One photograph of the chart: the detected patch centres as photographed (pixels) and the same patches on the
// chart's plane (mm, z = 0).
struct CalibrationView {
  std::vector<std::array<double, 2>> image_px;
  std::vector<std::array<double, 2>> chart_mm;
};

// calibrateCamera (OpenCV) with tangential distortion and k3 held at 0 (the model scene.json carries); sigma from
// OpenCV's standard deviations of the intrinsics (the Jacobian at the solution, scaled by the residuals). Throws
// Error(bad_parameter) for fewer than 3 photographs, a photograph with fewer than 20 points or mismatched lists,
// and Error(bad_data) when the solution is not a lens (focal lengths ≤ 0, principal point outside the frame).
LensCalibration calibrate_lens(const std::vector<CalibrationView>& views, int width_px, int height_px);

// What the operator states of a calibration: the body, the lens, its settings, the day (`colorlab lens calibrate
// --camera …`, the lens-calibration campaign's parameters).
struct LensIdentity {
  std::string camera, lens, focus, date;
  std::optional<double> focal_length_mm;
};

// One located photograph of the chart: each patch's centroid as photographed (the locator's observed centre), in the
// chart layout's order; nullopt where the patch was not detected.
using ObservedCentres = std::vector<std::optional<std::array<double, 2>>>;

// The lab's calibration from located chart photographs, as `colorlab lens calibrate` and the lens-calibration campaign
// make it: each photograph's detected centroids against the patches' centres on the chart's plane (the layout's grid
// units: the chart's scale does not enter the intrinsics), calibrate_lens over them, named and dated by `who`, its
// source "<by>: OpenCV calibrateCamera over N photographs of the <chart's name> (detected patch centres)". `chart`:
// "sg" or "cc24". Throws as calibrate_lens; Error(bad_parameter) for a photograph whose list is not the chart's
// length, or an unknown chart.
LensCalibration calibrate_lens_from_chart(const std::string& chart, const std::vector<ObservedCentres>& photographs, int width_px,
                                          int height_px, const LensIdentity& who, const std::string& by);

// The [[lens]] tables of a lab file (none: empty); lens_toml.hpp says what they hold and refuse.
std::vector<LensCalibration> lenses_from_file(const std::string& path);
std::string lens_to_toml(const LensCalibration& l);  // one [[lens]] table, to paste into the lab configuration

nlohmann::json lens_to_json(const LensCalibration& l);
// Validates as the TOML does; `where` names the source in messages (Error bad_data).
LensCalibration lens_from_json(const nlohmann::json& j, const std::string& where);

// The calibration for a photograph of width × height: the one named `name` when given (else Error bad_parameter
// listing the names), otherwise the only one of that size; none of that size: nullopt; several: Error
// bad_parameter asking for a name.
std::optional<LensCalibration> choose_lens(const std::vector<LensCalibration>& lenses, const std::string& name, int width_px,
                                           int height_px);

}  // namespace colorlab::verify
