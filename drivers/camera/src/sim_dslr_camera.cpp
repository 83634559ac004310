#include "colorlab/drivers/camera/sim_dslr_camera.hpp"

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "colorlab/drivers/camera/gphoto2_camera.hpp"
#include "colorlab/drivers/unix_line_client.hpp"

namespace colorlab::drivers::camera {

using nlohmann::json;

namespace {

// Short enough for the transcript, long enough to show what the camera said.
std::string clip(std::string s) {
  constexpr std::size_t kMax = 160;
  if (s.size() > kMax) s = s.substr(0, kMax) + "…";
  return s;
}

// json's value() throws its type_error for a field of another type: a field is read only if it is text.
std::string text_field(const json& answer, const char* key, const std::string& otherwise) {
  return answer.contains(key) && answer[key].is_string() ? answer[key].get<std::string>() : otherwise;
}

// json's get<int>() of 1e300 is undefined behaviour and of 2.5 a silent truncation: integers in range only.
template <class T>
T integer_of(const json& v, const std::string& what) {
  if (v.is_number_unsigned() && v.get<std::uint64_t>() <= static_cast<std::uint64_t>(std::numeric_limits<T>::max())) {
    return static_cast<T>(v.get<std::uint64_t>());
  }
  if (v.is_number_integer() && !v.is_number_unsigned() && v.get<std::int64_t>() >= 0 &&
      static_cast<std::uint64_t>(v.get<std::int64_t>()) <= static_cast<std::uint64_t>(std::numeric_limits<T>::max())) {
    return static_cast<T>(v.get<std::int64_t>());
  }
  throw Error(ErrorClass::protocol_error, "simulated DSLR: " + what + " is " + v.dump() + ", not a count",
              "driver and simulator disagree about the tethered-camera protocol");
}

// The protocol's error codes (docs/simulator.md, "Tethered-camera protocol") as colorlab errors.
Error answer_error(const json& answer, const std::string& camera, const std::string& cmd) {
  const std::string code = text_field(answer, "error", "?");
  const std::string text = camera + ": " + cmd + " refused: " + text_field(answer, "message", code);
  if (code == "busy") {
    return Error(ErrorInfo{
        .cls = ErrorClass::conflict,
        .message = text,
        .hint = "the camera is still writing to its card; wait and retry",
        .device_code = "simdslr:busy",
        .retryable = true,
    });
  }
  if (code == "bad_value") {
    return Error(ErrorInfo{
        .cls = ErrorClass::bad_parameter,
        .message = text,
        .hint = "see the camera's limits",
        .device_code = "simdslr:bad_value",
    });
  }
  if (code == "in_use") {
    return Error(ErrorInfo{
        .cls = ErrorClass::conflict,
        .message = text,
        .hint = "another program holds the camera; only one connection is served at a time",
        .device_code = "simdslr:in_use",
        .retryable = true,
    });
  }
  if (code == "failed") {
    return Error(ErrorInfo{
        .cls = ErrorClass::hardware_fail,
        .message = text,
        .hint = "the camera could not write its files: check the capture directory's disk",
        .device_code = "simdslr:failed",
        .retryable = true,
    });
  }
  // bad_request, not_found or a code this driver does not know: the two sides disagree.
  return Error(ErrorInfo{
      .cls = ErrorClass::protocol_error,
      .message = text,
      .hint = "driver and simulator disagree about the tethered-camera protocol (docs/simulator.md)",
      .device_code = "simdslr:" + code,
  });
}

std::vector<std::uint8_t> read_whole_file(const std::filesystem::path& path, std::uint64_t expected_bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw Error(ErrorClass::protocol_error, "the camera named " + path.string() + " but it cannot be read",
                "the capture directory must be readable by colorlabd");
  }
  std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (bytes.size() != expected_bytes) {
    throw Error(ErrorClass::bad_data,
                path.string() + " has " + std::to_string(bytes.size()) + " bytes, the camera announced " +
                    std::to_string(expected_bytes),
                "the file changed after the camera wrote it; capture again");
  }
  return bytes;
}

template <class T>
std::vector<T> list_of(const json& limits, const char* key) {
  std::vector<T> out;
  if (limits.contains(key)) {
    for (const auto& v : limits.at(key)) {
      if constexpr (std::is_integral_v<T>) {
        out.push_back(integer_of<T>(v, std::string("limits.") + key));
      } else {
        out.push_back(v.get<T>());
      }
    }
  }
  return out;
}

CameraSettings settings_from(const json& s) {
  CameraSettings c;
  if (s.contains("iso")) c.iso = integer_of<int>(s["iso"], "settings.iso");
  if (s.contains("shutter")) c.shutter_s = parse_shutter_label(s["shutter"].get<std::string>());
  if (s.contains("aperture")) c.aperture_f = s["aperture"].get<double>();
  if (s.contains("image_format")) c.image_format = image_format_from_string(s["image_format"].get<std::string>());
  return c;
}

}  // namespace

SimDslrCamera::SimDslrCamera(SimDslrOptions options)
    : Camera("cam-simdslr", CameraIdentity{CameraKind::dslr, "", "simulated DSLR", "", options.socket_path}),
      options_(std::move(options)),
      link_(std::make_unique<UnixLineClient>("simulated DSLR at " + options_.socket_path)) {
  if (options_.socket_path.empty()) {
    throw Error(ErrorClass::bad_parameter, "a simulated DSLR needs its socket path",
                "port = the path colorlab-sim announces for its \"simdslr\" instrument");
  }
}

SimDslrCamera::~SimDslrCamera() { shutdown(); }

json SimDslrCamera::request(json req, std::chrono::milliseconds timeout) {
  const std::string cmd = req.value("cmd", std::string("?"));
  const std::uint64_t id = next_id_++;
  req["id"] = id;
  const auto deadline = UnixLineClient::Clock::now() + timeout;
  const std::string line = req.dump();
  note("> " + clip(line));
  link_->send_line(line, deadline);
  for (;;) {
    const std::string text = link_->read_line(deadline);
    json answer = json::parse(text, nullptr, false);
    if (answer.is_discarded() || !answer.is_object() || !answer.contains("ok") || !answer["ok"].is_boolean()) {
      note("< (malformed) " + clip(text));
      link_->close();  // after a garbled line nothing on this connection can be trusted
      throw Error(ErrorInfo{.cls = ErrorClass::protocol_error,
                            .message = name() + ": the answer to " + cmd + " is not a protocol line: " + clip(text),
                            .hint = "driver and simulator disagree about the tethered-camera protocol; reconnect",
                            .retryable = true});
    }
    // An answer with another id is the late answer to an earlier request that already timed out:
    // dropped. One with a null id refuses a request the camera could not read.
    if (answer.contains("id") && answer["id"].is_number_unsigned() && answer["id"].get<std::uint64_t>() != id) {
      note("< (stale, dropped) " + clip(text));
      continue;
    }
    note("< " + clip(text));
    if (!answer["ok"].get<bool>()) throw answer_error(answer, name(), cmd);
    if (!answer.contains("id") || answer["id"].is_null()) {
      throw Error(ErrorClass::protocol_error, name() + ": an answer to " + cmd + " without the request's id",
                  "driver and simulator disagree about the tethered-camera protocol");
    }
    return answer;
  }
}

Camera::Connected SimDslrCamera::do_connect() {
  link_->connect(options_.socket_path);
  next_id_ = 1;
  const json who = request({{"cmd", "identify"}}, options_.request_timeout);
  try {
    Connected c;
    c.identity = CameraIdentity{CameraKind::dslr, who.at("make").get<std::string>(), who.at("model").get<std::string>(),
                                who.at("serial").get<std::string>(), options_.socket_path};
    const json& l = who.at("limits");
    c.limits.iso = list_of<int>(l, "iso");
    for (const auto& label : list_of<std::string>(l, "shutter")) {
      if (auto s = parse_shutter_label(label)) {
        c.limits.shutter_s.push_back(*s);
        shutter_labels_.emplace_back(*s, label);
      }
    }
    c.limits.aperture_f = list_of<double>(l, "aperture");
    for (const auto& f : list_of<std::string>(l, "image_formats")) c.limits.image_formats.push_back(image_format_from_string(f));
    c.settings = settings_from(who.at("settings"));
    return c;
  } catch (const json::exception& e) {
    link_->close();
    throw Error(ErrorClass::protocol_error, name() + ": identify answer lacks a field: " + e.what(),
                "driver and simulator disagree about the tethered-camera protocol");
  }
}

void SimDslrCamera::do_disconnect() noexcept {
  link_->close();
  shutter_labels_.clear();
}

void SimDslrCamera::do_configure(const CameraSettings& s) {
  if (s.exposure_us || s.gain || s.pixel_format) {
    throw Error(ErrorClass::unsupported, name() + " takes iso, shutter, aperture and image format only");
  }
  json req{{"cmd", "configure"}};
  if (s.iso) req["iso"] = *s.iso;
  if (s.shutter_s) {
    // Sent as the camera's own label, found by value (limits were validated before this runs).
    for (const auto& [seconds, label] : shutter_labels_) {
      if (std::abs(seconds - *s.shutter_s) <= 0.01 * seconds) req["shutter"] = label;
    }
  }
  if (s.aperture_f) req["aperture"] = *s.aperture_f;
  if (s.image_format) req["image_format"] = std::string(to_string(*s.image_format));
  request(std::move(req), options_.request_timeout);
}

CapturedFrame SimDslrCamera::do_capture_frame(std::size_t index) {
  const double shutter = settings().shutter_s.value_or(0);
  const auto timeout = options_.capture_timeout + std::chrono::milliseconds(static_cast<long long>(std::ceil(shutter * 1000)));
  const json answer = request({{"cmd", "capture"}}, timeout);

  CapturedFrame frame;
  frame.timestamp = std::chrono::system_clock::now();
  std::vector<std::string> names;
  try {
    for (const auto& f : answer.at("files")) {
      const std::string file_name = f.at("name").get<std::string>();
      const std::filesystem::path path = f.at("path").get<std::string>();
      auto bytes = read_whole_file(path, integer_of<std::uint64_t>(f.at("bytes"), "a file's bytes"));
      names.push_back(file_name);
      std::filesystem::path kept = path;
      if (!options_.keep_dir.empty()) {
        std::filesystem::create_directories(options_.keep_dir);
        kept = options_.keep_dir / file_name;
        std::ofstream out(kept, std::ios::binary);
        out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
        if (!out) throw Error(ErrorClass::io_error, "cannot save " + kept.string(), "check disk space and permissions");
      }
      // The raw goes first in saved_files, its sidecars after it, as with a real DSLR's download.
      if (frame.file_bytes.empty() && f.value("type", std::string()) == "raw" && is_raw_file_name(file_name)) {
        frame.file_bytes = std::move(bytes);
        frame.file_name = file_name;
        frame.saved_files.insert(frame.saved_files.begin(), kept);
      } else {
        frame.saved_files.push_back(kept);
      }
    }
  } catch (const json::exception& e) {
    throw Error(ErrorClass::protocol_error, name() + ": capture answer of frame " + std::to_string(index) + " is malformed: " + e.what(),
                "driver and simulator disagree about the tethered-camera protocol");
  }
  if (frame.file_bytes.empty()) {
    throw Error(ErrorClass::protocol_error, name() + ": capture of frame " + std::to_string(index) + " named no raw file",
                "set the image format to raw, raw+jpeg or raw+jpeg+tiff");
  }
  if (!options_.keep_dir.empty()) request({{"cmd", "delete"}, {"names", names}}, options_.request_timeout);
  return frame;
}

}  // namespace colorlab::drivers::camera
