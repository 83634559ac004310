#pragma once
// The camera's spectral sensitivities on the scene's radiance grid (380–730 nm, 5 nm).
#include <array>
#include <string>

#include "colorlab/sim/camera/camera_model.hpp"

namespace colorlab::sim::camera::detail {

struct Sensitivities {
  std::array<Spectrum, 3> rgb;
  std::string source;
};

// From config.sensitivity_file, else the shared set's Canon 20D curves, else parametric. Scaled so that the
// green channel's response to D65 equals its luminance (then exposure in cd·s/m² maps to green electrons).
Sensitivities load_sensitivities(const CameraConfig& config, const Scene& scene);

}  // namespace colorlab::sim::camera::detail
