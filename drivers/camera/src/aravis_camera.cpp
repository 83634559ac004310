#include "colorlab/drivers/camera/aravis_camera.hpp"

#include <arv.h>

#include <algorithm>
#include <cstring>

#include "colorlab/core/log.hpp"

namespace colorlab::drivers::camera {

namespace {

Error aravis_error(GError* err, std::string_view operation) {
  ErrorInfo info;
  info.message = "Aravis " + std::string(operation) + " failed";
  if (err) {
    info.message += std::string(": ") + err->message;
    info.device_code = std::string(g_quark_to_string(err->domain)) + ":" + std::to_string(err->code);
  }
  info.cls = ErrorClass::device_error;
  info.hint = "see the camera's GenICam feature list (arv-tool-0.8 features)";
  if (err && err->domain == ARV_DEVICE_ERROR) {
    switch (err->code) {
      case ARV_DEVICE_ERROR_TIMEOUT:
        info.cls = ErrorClass::timeout;
        info.hint = "the camera did not answer; check the network link and the camera's power";
        info.retryable = true;
        break;
      case ARV_DEVICE_ERROR_NOT_CONNECTED:
      case ARV_DEVICE_ERROR_TRANSFER_ERROR:
        info.cls = ErrorClass::no_comms;
        info.hint = "link to the camera lost; check the cable/network and reconnect";
        info.retryable = true;
        break;
      case ARV_DEVICE_ERROR_NOT_FOUND:
        info.cls = ErrorClass::not_found;
        info.hint = "no camera with that id; list them with `arv-tool-0.8` and check the config";
        break;
      case ARV_DEVICE_ERROR_NOT_CONTROLLER:
      case ARV_DEVICE_ERROR_PROTOCOL_ERROR_BUSY:
      case ARV_DEVICE_ERROR_PROTOCOL_ERROR_ACCESS_DENIED:
        info.cls = ErrorClass::conflict;
        info.hint = "another application controls the camera; close it (arv-viewer, vendor tools)";
        info.retryable = true;
        break;
      case ARV_DEVICE_ERROR_FEATURE_NOT_FOUND:
      case ARV_DEVICE_ERROR_WRONG_FEATURE:
        info.cls = ErrorClass::unsupported;
        info.hint = "the camera lacks this GenICam feature";
        break;
      case ARV_DEVICE_ERROR_PROTOCOL_ERROR:
      case ARV_DEVICE_ERROR_PROTOCOL_ERROR_NOT_IMPLEMENTED:
      case ARV_DEVICE_ERROR_PROTOCOL_ERROR_INVALID_ADDRESS:
      case ARV_DEVICE_ERROR_PROTOCOL_ERROR_BAD_ALIGNMENT:
        info.cls = ErrorClass::protocol_error;
        break;
      case ARV_DEVICE_ERROR_PROTOCOL_ERROR_INVALID_PARAMETER:
      case ARV_DEVICE_ERROR_PROTOCOL_ERROR_WRITE_PROTECT:
      case ARV_DEVICE_ERROR_INVALID_PARAMETER:
        info.cls = ErrorClass::bad_parameter;
        info.hint = "value rejected by the camera; stay inside limits() and stop acquisition first";
        break;
      default:
        break;
    }
  } else if (err && err->domain == ARV_GC_ERROR) {
    info.cls = (err->code == ARV_GC_ERROR_OUT_OF_RANGE || err->code == ARV_GC_ERROR_ENUM_ENTRY_NOT_FOUND)
                   ? ErrorClass::bad_parameter
                   : ErrorClass::unsupported;
    info.hint = "the camera's GenICam description does not allow this value";
  }
  if (err) g_error_free(err);
  return Error(std::move(info));
}

// Aravis reports errors through GError out-parameters; this turns each into a typed throw.
class Check {
 public:
  explicit Check(std::string_view op) : op_(op) {}
  ~Check() noexcept(false) {
    if (err_ && std::uncaught_exceptions() == 0) throw aravis_error(err_, op_);
    if (err_) g_error_free(err_);
  }
  operator GError**() { return &err_; }  // NOLINT: passed straight to Aravis

 private:
  std::string_view op_;
  GError* err_ = nullptr;
};

std::string dup_string(const char* s) { return s ? s : ""; }

struct PixelInfo {
  PixelFormat format;
  ArvPixelFormat arv;
  std::uint16_t white;
  std::uint32_t bits;
  bool mosaic;
};

PixelInfo pixel_info(ArvPixelFormat f) {
  switch (f) {
    case ARV_PIXEL_FORMAT_BAYER_RG_12: return {PixelFormat::bayer_rg12, f, 4095, 12, true};
    case ARV_PIXEL_FORMAT_BAYER_RG_16: return {PixelFormat::bayer_rg16, f, 65535, 16, true};
    case ARV_PIXEL_FORMAT_MONO_16: return {PixelFormat::mono16, f, 65535, 16, false};
    default:
      throw Error(
          ErrorClass::unsupported,
          "camera delivers pixel format 0x" + [&] {
            char b[16];
            std::snprintf(b, sizeof b, "%08x", static_cast<unsigned>(f));
            return std::string(b);
          }(),
          "configure BayerRG12, BayerRG16 or Mono16: colorlab needs unpacked 16-bit samples");
  }
}

}  // namespace

struct AravisCamera::Device {
  ArvCamera* camera = nullptr;
  ArvStream* stream = nullptr;
  gulong control_lost_handler = 0;
  std::atomic<bool> control_lost{false};
  std::size_t payload = 0;

  ~Device() {
    if (stream) g_object_unref(stream);
    if (camera) {
      if (control_lost_handler) g_signal_handler_disconnect(arv_camera_get_device(camera), control_lost_handler);
      g_object_unref(camera);
    }
  }
};

AravisCamera::AravisCamera(AravisOptions options)
    : Camera("cam-aravis", CameraIdentity{CameraKind::genicam, "", "", "", options.device_id}),
      options_(std::move(options)) {}

AravisCamera::~AravisCamera() { shutdown(); }

Camera::Connected AravisCamera::do_connect() {
  auto d = std::make_unique<Device>();
  const char* id = options_.device_id.empty() ? nullptr : options_.device_id.c_str();
  GError* err = nullptr;
  d->camera = arv_camera_new(id, &err);
  if (!d->camera) {
    Error e = aravis_error(err, "open camera '" + options_.device_id + "'");
    if (e.cls() == ErrorClass::device_error) {  // arv_camera_new reports "not found" loosely
      throw Error(ErrorInfo{.cls = ErrorClass::no_comms,
                            .message = e.what(),
                            .hint = "check the camera's IP/id, network and power",
                            .device_code = e.info().device_code,
                            .retryable = true});
    }
    throw e;
  }
  d->control_lost_handler =
      g_signal_connect(arv_camera_get_device(d->camera), "control-lost",
                       G_CALLBACK(+[](ArvDevice*, gpointer flag) { static_cast<std::atomic<bool>*>(flag)->store(true); }),
                       &d->control_lost);

  Connected c;
  c.identity.kind = CameraKind::genicam;
  c.identity.make = dup_string(arv_camera_get_vendor_name(d->camera, Check("read vendor name")));
  c.identity.model = dup_string(arv_camera_get_model_name(d->camera, Check("read model name")));
  c.identity.serial = dup_string(arv_camera_get_device_serial_number(d->camera, Check("read serial number")));
  c.identity.port = options_.device_id;

  Range exposure, gain;
  arv_camera_get_exposure_time_bounds(d->camera, &exposure.min, &exposure.max, Check("read exposure bounds"));
  c.limits.exposure_us = exposure;
  if (arv_camera_is_gain_available(d->camera, nullptr)) {
    arv_camera_get_gain_bounds(d->camera, &gain.min, &gain.max, Check("read gain bounds"));
    c.limits.gain = gain;
  }
  guint n = 0;
  const char** formats = arv_camera_dup_available_pixel_formats_as_strings(d->camera, &n, Check("list pixel formats"));
  for (guint i = 0; i < n; ++i) {
    for (auto f : {PixelFormat::bayer_rg12, PixelFormat::bayer_rg16, PixelFormat::mono16}) {
      if (formats[i] && to_string(f) == formats[i]) c.limits.pixel_formats.push_back(f);
    }
  }
  g_free(formats);

  Region r;
  if (options_.region) {
    r = *options_.region;
  } else {
    arv_camera_get_sensor_size(d->camera, &r.width, &r.height, Check("read sensor size"));
  }
  arv_camera_set_region(d->camera, r.x, r.y, r.width, r.height, Check("set region of interest"));
  if (options_.frame_rate_hz && arv_camera_is_frame_rate_available(d->camera, nullptr)) {
    arv_camera_set_frame_rate(d->camera, *options_.frame_rate_hz, Check("set frame rate"));
  }
  c.settings.exposure_us = arv_camera_get_exposure_time(d->camera, Check("read exposure"));
  if (c.limits.gain) c.settings.gain = arv_camera_get_gain(d->camera, Check("read gain"));
  const std::string pf = dup_string(arv_camera_get_pixel_format_as_string(d->camera, Check("read pixel format")));
  for (auto f : c.limits.pixel_formats) {
    if (to_string(f) == pf) c.settings.pixel_format = f;
  }
  device_ = std::move(d);
  return c;
}

void AravisCamera::do_disconnect() noexcept { device_.reset(); }

void AravisCamera::do_configure(const CameraSettings& s) {
  ArvCamera* cam = device_->camera;
  if (s.pixel_format) {
    arv_camera_set_pixel_format_from_string(cam, std::string(to_string(*s.pixel_format)).c_str(),
                                            Check("set pixel format"));
  }
  if (s.exposure_us) arv_camera_set_exposure_time(cam, *s.exposure_us, Check("set exposure time"));
  if (s.gain) arv_camera_set_gain(cam, *s.gain, Check("set gain"));
}

void AravisCamera::do_begin_series(std::size_t) {
  Device& d = *device_;
  if (d.control_lost.load()) {
    throw Error(ErrorInfo{.cls = ErrorClass::no_comms,
                          .message = name() + ": control of the camera was lost",
                          .hint = "the heartbeat stopped (network down, camera rebooted); reconnect",
                          .retryable = true});
  }
  failed_buffers_ = 0;
  pixel_info(arv_camera_get_pixel_format(d.camera, Check("read pixel format")));  // reject packed formats early
  if (options_.software_trigger) {
    arv_camera_set_trigger(d.camera, "Software", Check("enable software trigger"));
  } else {
    arv_camera_clear_triggers(d.camera, Check("clear triggers"));
  }
  arv_camera_set_acquisition_mode(d.camera, ARV_ACQUISITION_MODE_CONTINUOUS, Check("set acquisition mode"));
  d.payload = arv_camera_get_payload(d.camera, Check("read payload size"));
  d.stream = arv_camera_create_stream(d.camera, nullptr, nullptr, Check("create stream"));
  if (ARV_IS_GV_STREAM(d.stream)) {
    g_object_set(d.stream, "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_FIXED, "socket-buffer-size",
                 static_cast<gint>(options_.socket_buffer_bytes), nullptr);
  }
  for (unsigned i = 0; i < std::max(1U, options_.n_buffers); ++i) {
    arv_stream_push_buffer(d.stream, arv_buffer_new(d.payload, nullptr));
  }
  arv_camera_start_acquisition(d.camera, Check("start acquisition"));
}

CapturedFrame AravisCamera::do_capture_frame(std::size_t index) {
  Device& d = *device_;
  const auto timeout_us = static_cast<guint64>(options_.frame_timeout.count()) * 1000U;
  std::string last_problem = "no buffer within " + std::to_string(options_.frame_timeout.count()) + " ms";
  for (unsigned attempt = 0; attempt <= options_.max_retries_per_frame; ++attempt) {
    if (d.control_lost.load()) {
      throw Error(ErrorInfo{.cls = ErrorClass::no_comms,
                            .message = name() + ": control lost at frame " + std::to_string(index),
                            .hint = "network link or camera power lost; reconnect",
                            .retryable = true});
    }
    if (options_.software_trigger) arv_camera_software_trigger(d.camera, Check("software trigger"));
    ArvBuffer* buffer = arv_stream_timeout_pop_buffer(d.stream, timeout_us);
    if (!buffer) {
      ++failed_buffers_;
      continue;
    }
    struct Requeue {
      ArvStream* s;
      ArvBuffer* b;
      ~Requeue() { arv_stream_push_buffer(s, b); }
    } requeue{d.stream, buffer};
    if (arv_buffer_get_status(buffer) != ARV_BUFFER_STATUS_SUCCESS) {
      ++failed_buffers_;
      last_problem = "buffer status " + std::to_string(static_cast<int>(arv_buffer_get_status(buffer)));
      continue;
    }
    const PixelInfo px = pixel_info(arv_buffer_get_image_pixel_format(buffer));
    gint x = 0, y = 0, w = 0, h = 0;
    arv_buffer_get_image_region(buffer, &x, &y, &w, &h);
    std::size_t size = 0;
    const void* data = arv_buffer_get_image_data(buffer, &size);
    const std::size_t n_pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    if (!data || w <= 0 || h <= 0 || size < n_pixels * 2) {
      ++failed_buffers_;
      last_problem = "short buffer (" + std::to_string(size) + " bytes for " + std::to_string(w) + "x" +
                     std::to_string(h) + ")";
      continue;
    }
    CapturedFrame frame;
    const guint64 ts = arv_buffer_get_system_timestamp(buffer);
    frame.timestamp = std::chrono::system_clock::time_point(
        std::chrono::duration_cast<std::chrono::system_clock::duration>(std::chrono::nanoseconds(ts)));
    OwnedRawImage img;
    img.storage.resize(n_pixels);
    std::memcpy(img.storage.data(), data, n_pixels * 2);  // GenICam 16-bit containers are little-endian
    RawImage& m = img.meta;
    m.row_stride = m.raw_width = m.width = static_cast<std::size_t>(w);
    m.raw_height = m.height = static_cast<std::size_t>(h);
    m.white_level = px.white;
    m.black_level.fill(options_.black_level);
    m.bits_per_sample = px.bits;
    // The Bayer phase is fixed by the sensor origin: an odd ROI offset shifts RGGB.
    const CfaPattern rggb = CfaPattern::rggb();
    m.cfa = px.mosaic ? CfaPattern{} : CfaPattern::monochrome();
    if (px.mosaic) {
      for (int r = 0; r < 2; ++r) {
        for (int c = 0; c < 2; ++c) m.cfa.cell[r][c] = rggb.at(static_cast<std::size_t>(r + y), static_cast<std::size_t>(c + x));
      }
    }
    frame.pixels = std::move(img);
    return frame;
  }
  throw Error(ErrorInfo{.cls = ErrorClass::timeout,
                        .message = name() + ": frame " + std::to_string(index) + " failed after " +
                                   std::to_string(options_.max_retries_per_frame + 1) + " attempts (" + last_problem + ")",
                        .hint = "check the network (MTU, socket buffer, packet loss) and the trigger settings",
                        .retryable = true});
}

void AravisCamera::do_end_series() noexcept {
  if (!device_) return;
  GError* err = nullptr;
  arv_camera_stop_acquisition(device_->camera, &err);
  if (err) {
    log::warning("camera", name() + ": stop acquisition: " + err->message);
    g_error_free(err);
  }
  if (device_->stream) {
    g_object_unref(device_->stream);
    device_->stream = nullptr;
  }
}

}  // namespace colorlab::drivers::camera
