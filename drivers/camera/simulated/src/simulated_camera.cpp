#include "colorlab/drivers/camera/simulated_camera.hpp"

#include <cstdio>
#include <fstream>
#include <iterator>
#include <thread>

#include "colorlab/sim/camera/dng.hpp"
#include "colorlab/sim/camera/eos20d.hpp"
#include "colorlab/sim/camera/processed.hpp"

namespace colorlab::drivers::camera {

namespace {

using sim::camera::eos20d::kShutterLabels;

CameraLimits eos20d_limits() {
  CameraLimits l;
  l.iso.assign(std::begin(sim::camera::eos20d::kIsos), std::end(sim::camera::eos20d::kIsos));
  for (const char* s : kShutterLabels) l.shutter_s.push_back(*parse_shutter_label(s));
  l.aperture_f.assign(std::begin(sim::camera::eos20d::kApertures), std::end(sim::camera::eos20d::kApertures));
  l.image_formats = {ImageFormat::raw, ImageFormat::raw_and_jpeg};
  return l;
}

std::vector<std::uint8_t> read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorClass::io_error, "cannot read back " + path.string(), "check the capture directory");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

SimulatedCamera::SimulatedCamera(SimulatedCameraOptions options)
    : Camera("cam-sim", CameraIdentity{CameraKind::simulated, "colorlab", "Simulated EOS-20D", options.serial,
                                       options.capture_dir.string()}),
      options_(std::move(options)) {
  if (!options_.model) {
    throw Error(ErrorClass::bad_parameter, "SimulatedCamera needs a CameraModel", "pass options.model");
  }
  if (options_.capture_dir.empty()) {
    throw Error(ErrorClass::bad_parameter, "SimulatedCamera needs a capture directory", "set options.capture_dir");
  }
}

SimulatedCamera::~SimulatedCamera() { shutdown(); }

void SimulatedCamera::inject_fault(CameraFault fault, std::size_t at_frame) {
  std::lock_guard lock(fault_mutex_);
  fault_ = std::make_pair(fault, at_frame);
}

void SimulatedCamera::clear_faults() {
  std::lock_guard lock(fault_mutex_);
  fault_.reset();
}

sim::camera::CameraSettings SimulatedCamera::model_settings() const {
  std::lock_guard lock(fault_mutex_);
  return exposure_;
}

Camera::Connected SimulatedCamera::do_connect() {
  std::error_code ec;
  std::filesystem::create_directories(options_.capture_dir, ec);
  if (ec) {
    throw Error(ErrorClass::io_error,
                "cannot create capture directory " + options_.capture_dir.string() + ": " +
                    ec.message(),
                "check the path and permissions");
  }
  unplugged_ = false;
  color_matrix_ = options_.model->xyz_to_camera_d65();
  neutral_ = options_.model->as_shot_neutral();
  Connected c;
  c.identity = CameraIdentity{CameraKind::simulated, "colorlab", "Simulated EOS-20D", options_.serial,
                              options_.capture_dir.string()};
  c.limits = eos20d_limits();
  const auto e = model_settings();
  c.settings.iso = e.iso;
  c.settings.shutter_s = e.shutter_s;
  c.settings.aperture_f = e.f_number;
  c.settings.image_format = format_;
  return c;
}

void SimulatedCamera::do_disconnect() noexcept {}

void SimulatedCamera::do_configure(const CameraSettings& s) {
  if (unplugged_) {
    throw Error(ErrorInfo{
        .cls = ErrorClass::no_comms,
        .message = name() + " is unplugged",
        .hint = "reconnect the camera",
        .retryable = true,
    });
  }
  std::lock_guard lock(fault_mutex_);
  if (s.iso) exposure_.iso = *s.iso;
  if (s.shutter_s) exposure_.shutter_s = *s.shutter_s;
  if (s.aperture_f) exposure_.f_number = *s.aperture_f;
  if (s.image_format) format_ = *s.image_format;
}

CapturedFrame SimulatedCamera::do_capture_frame(std::size_t index) {
  std::optional<CameraFault> fault;
  {
    std::lock_guard lock(fault_mutex_);
    if (fault_ && fault_->second == index) {
      fault = fault_->first;
      fault_.reset();
    }
  }
  if (unplugged_ || fault == CameraFault::disconnect) {
    unplugged_ = true;
    throw Error(ErrorInfo{.cls = ErrorClass::no_comms,
                          .message = name() + " disappeared during capture of frame " + std::to_string(index),
                          .hint = "check the USB cable and camera power (battery), then reconnect",
                          .transport_code = "ENODEV",
                          .retryable = true});
  }
  if (fault == CameraFault::busy) {
    throw Error(ErrorInfo{.cls = ErrorClass::conflict,
                          .message = name() + " is busy (frame " + std::to_string(index) + ")",
                          .hint = "the camera is still writing to its card; wait and retry",
                          .device_code = "gphoto2:-110",
                          .retryable = true});
  }
  if (fault == CameraFault::capture_timeout) {
    std::this_thread::sleep_for(options_.timeout_after);
    throw Error(ErrorInfo{.cls = ErrorClass::timeout,
                          .message = name() + ": no image within " + std::to_string(options_.timeout_after.count()) +
                                     " ms for frame " + std::to_string(index),
                          .hint = "check the camera (autofocus hunting? card full?) and retry",
                          .retryable = true});
  }

  const auto exposure = model_settings();
  const ImageFormat format = [&] {
    std::lock_guard lock(fault_mutex_);
    return format_;
  }();
  const std::uint64_t shot = shots_.fetch_add(1);
  sim::camera::RawFrame raw = options_.model->render(exposure, shot);
  if (options_.extra_capture_time.count() > 0) std::this_thread::sleep_for(options_.extra_capture_time);

  char name_buf[32];
  std::snprintf(name_buf, sizeof name_buf, "IMG_%06llu.DNG", static_cast<unsigned long long>(shot));
  const auto path = options_.capture_dir / name_buf;
  sim::camera::DngMetadata meta;
  meta.color_matrix1 = color_matrix_;
  meta.as_shot_neutral = neutral_;
  sim::camera::write_dng(path, raw, meta);

  CapturedFrame frame;
  frame.timestamp = std::chrono::system_clock::now();
  frame.file_name = name_buf;
  if (format == ImageFormat::raw_and_jpeg || options_.write_tiff16) {
    const auto developed = sim::camera::develop(raw, *options_.model);
    auto sidecar = path;
    if (format == ImageFormat::raw_and_jpeg) {
      try {
        sidecar.replace_extension(".JPG");
        sim::camera::write_jpeg(sidecar, developed);
      } catch (const Error& e) {
        if (e.cls() != ErrorClass::unsupported) throw;
        sidecar.replace_extension(".TIF");  // built without libjpeg
        sim::camera::write_tiff(sidecar, developed, 8);
      }
      frame.saved_files.push_back(sidecar);
    }
    if (options_.write_tiff16) {
      sidecar.replace_extension(".TIFF");
      sim::camera::write_tiff(sidecar, developed, 16);
      frame.saved_files.push_back(sidecar);
    }
  }
  frame.file_bytes = read_file(path);
  if (options_.keep_files) {
    frame.saved_files.insert(frame.saved_files.begin(), path);
  } else {
    std::error_code ec;
    std::filesystem::remove(path, ec);
  }
  return frame;
}

}  // namespace colorlab::drivers::camera
