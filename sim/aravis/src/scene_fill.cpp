#include "colorlab/sim/aravis/scene_fill.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>

namespace colorlab::sim::aravis {

sim::camera::CameraSettings model_settings_for(double exposure_us, double gain, double f_number) {
  sim::camera::CameraSettings s;
  s.f_number = f_number;
  s.shutter_s = std::max(exposure_us, 1.0) * 1e-6;
  s.iso = static_cast<int>(std::lround(std::clamp(100.0 * std::exp2(gain / 2.0), 50.0, 3200.0)));
  return s;
}

FillFunction scene_fill(std::shared_ptr<const sim::camera::CameraModel> model, double f_number) {
  // Aravis calls the fill from one camera thread; the frame buffer is kept between calls so a
  // full-size render does not reallocate 16 MB per frame.
  auto frame = std::make_shared<sim::camera::RawFrame>();
  auto mutex = std::make_shared<std::mutex>();
  return [model, f_number, frame, mutex](const FillRequest& req, std::span<std::uint16_t> out) {
    std::lock_guard lock(*mutex);
    model->render_into(*frame, model_settings_for(req.exposure_us, req.gain, f_number), req.frame_id);
    const int shift = req.pixel_format == "BayerRG12" ? 0 : 4;
    for (int r = 0; r < req.height; ++r) {
      const int sy = req.y + r;
      for (int c = 0; c < req.width; ++c) {
        const int sx = req.x + c;
        const bool inside = sx >= 0 && sy >= 0 && sx < frame->width && sy < frame->height;
        out[static_cast<std::size_t>(r * req.width + c)] =
            inside ? static_cast<std::uint16_t>(frame->at(sx, sy) << shift) : 0;
      }
    }
  };
}

GvFakeOptions scene_camera_options(std::shared_ptr<const sim::camera::CameraModel> model, double f_number) {
  GvFakeOptions o;
  o.sensor_width = model->width();
  o.sensor_height = model->height();
  o.fill = scene_fill(std::move(model), f_number);
  return o;
}

}  // namespace colorlab::sim::aravis
