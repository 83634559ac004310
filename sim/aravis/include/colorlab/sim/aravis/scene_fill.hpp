#pragma once
// Fill for the GigE Vision fake: frames rendered by the scene's CameraModel (12-bit RGGB counts
// with noise, defects and dust), cropped to the requested ROI. GenICam exposure and gain map to
// the model's shutter and ISO; the aperture is fixed, as on a machine-vision lens.
#include <memory>

#include "colorlab/sim/aravis/gv_fake_camera.hpp"
#include "colorlab/sim/camera/camera_model.hpp"

namespace colorlab::sim::aravis {

// exposure µs -> shutter s; GainRaw g (0..10) -> ISO 100 * 2^(g/2), clamped to 50..3200.
sim::camera::CameraSettings model_settings_for(double exposure_us, double gain, double f_number);

// 16-bit formats (BayerRG16, Mono16) carry the 12-bit counts shifted left by 4.
FillFunction scene_fill(std::shared_ptr<const sim::camera::CameraModel> model, double f_number = 4.0);

// Options for a GV fake whose sensor is the model's frame.
GvFakeOptions scene_camera_options(std::shared_ptr<const sim::camera::CameraModel> model, double f_number = 4.0);

}  // namespace colorlab::sim::aravis
