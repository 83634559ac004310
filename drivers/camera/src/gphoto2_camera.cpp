#include "colorlab/drivers/camera/gphoto2_camera.hpp"

#include <gphoto2/gphoto2.h>
#include <locale.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>

#include "colorlab/core/log.hpp"

namespace colorlab::drivers::camera {

namespace {

// The one thread that may call libgphoto2. A thread-local C locale keeps widget labels
// ("Full Image", "RAW") untranslated whatever the daemon's environment says.
WorkerThread& gphoto2_thread() {
  static WorkerThread* thread = [] {
    auto* t = new WorkerThread("gphoto2");  // lives for the process: libgphoto2 state does too
    t->submit([] {
       static locale_t c_locale = newlocale(LC_ALL_MASK, "C", static_cast<locale_t>(nullptr));
       uselocale(c_locale);
     }).get();
    return t;
  }();
  return *thread;
}

template <class F>
auto on_gphoto2_thread(F&& f) -> std::invoke_result_t<F> {
  WorkerThread& t = gphoto2_thread();
  if (t.on_this_thread()) return f();
  return t.submit(std::forward<F>(f)).get();
}

// A libgphoto2 call can block forever on a wedged USB link. Callers then stop waiting after the
// deadline and get Error(hardware_fail); the stuck call keeps the gphoto2 thread until it
// returns, and every later call fails fast until then. Lambdas passed here capture by value
// (shared Session, options), so a call that returns late touches nothing that has gone.
std::mutex g_stuck_mutex;
std::shared_future<void> g_stuck;  // ready once the overrunning call has returned

template <class F>
auto on_gphoto2_thread_within(std::chrono::milliseconds limit, const std::string& what, F f)
    -> std::invoke_result_t<F> {
  WorkerThread& t = gphoto2_thread();
  if (t.on_this_thread()) return f();
  {
    std::lock_guard lock(g_stuck_mutex);
    if (g_stuck.valid() && g_stuck.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
      throw Error(ErrorInfo{.cls = ErrorClass::hardware_fail,
                            .message = "libgphoto2 is still stuck in an earlier call; cannot " + what,
                            .hint = "unplug or power-cycle the camera; restart the daemon if this persists",
                            .retryable = true});
    }
  }
  auto result = t.submit(std::move(f));
  if (result.wait_for(limit) == std::future_status::timeout) {
    std::lock_guard lock(g_stuck_mutex);
    g_stuck = t.submit([] {}).share();  // runs right after the stuck call returns
    throw Error(ErrorInfo{.cls = ErrorClass::hardware_fail,
                          .message = "libgphoto2 " + what + " did not return within " +
                                     std::to_string(limit.count() / 1000) + " s",
                          .hint = "the USB link or the camera firmware is stuck: power-cycle the camera, then reconnect",
                          .retryable = true});
  }
  return result.get();
}

void check(int rc, std::string_view operation) {
  if (rc < GP_OK) throw gphoto2_error(rc, operation);
}

struct ListGuard {
  CameraList* list = nullptr;
  ListGuard() { check(gp_list_new(&list), "gp_list_new"); }
  ~ListGuard() { gp_list_free(list); }
};

struct FileGuard {
  CameraFile* file = nullptr;
  FileGuard() { check(gp_file_new(&file), "gp_file_new"); }
  ~FileGuard() { gp_file_unref(file); }
};

struct WidgetGuard {
  CameraWidget* w = nullptr;
  ~WidgetGuard() {
    if (w) gp_widget_free(w);
  }
};

std::string upper_extension(std::string_view name) {
  auto dot = name.rfind('.');
  if (dot == std::string_view::npos) return {};
  std::string ext(name.substr(dot + 1));
  for (char& c : ext) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return ext;
}

std::string basename_without_extension(std::string_view name) {
  auto dot = name.rfind('.');
  return std::string(name.substr(0, dot));
}

}  // namespace

bool is_raw_file_name(std::string_view name) {
  static const char* raw[] = {"CR2", "CR3", "CRW", "DNG", "NEF", "NRW", "ARW", "ORF", "RW2", "PEF", "RAF", "SRW"};
  const std::string ext = upper_extension(name);
  return std::any_of(std::begin(raw), std::end(raw), [&](const char* r) { return ext == r; });
}

Error gphoto2_error(int code, std::string_view operation) {
  ErrorInfo info;
  info.device_code = "gphoto2:" + std::to_string(code);
  info.transport_code = gp_result_as_string(code);
  info.message = "libgphoto2 " + std::string(operation) + " failed: " + info.transport_code;
  switch (code) {
    case GP_ERROR_TIMEOUT:
      info.cls = ErrorClass::timeout;
      info.hint = "the camera did not answer in time; check it is awake (auto power-off) and retry";
      info.retryable = true;
      break;
    case GP_ERROR_CAMERA_BUSY:
      info.cls = ErrorClass::conflict;
      info.hint = "the camera is busy (writing to the card, menu open); wait a moment and retry";
      info.retryable = true;
      break;
    case GP_ERROR_IO_USB_CLAIM:
    case GP_ERROR_IO_LOCK:
      info.cls = ErrorClass::conflict;
      info.hint = "another program holds the camera (gvfs-gphoto2-volume-monitor, a file manager); stop it";
      info.retryable = true;
      break;
    case GP_ERROR_NOT_SUPPORTED:
      info.cls = ErrorClass::unsupported;
      info.hint = "this camera/camlib cannot do that; for the EOS 20D set Communication to normal (not PTP) mode";
      break;
    case GP_ERROR_BAD_PARAMETERS:
      info.cls = ErrorClass::bad_parameter;
      info.hint = "a setting value is not one of the camera's choices";
      break;
    case GP_ERROR_IO:
    case GP_ERROR_IO_SUPPORTED_SERIAL:
    case GP_ERROR_IO_SUPPORTED_USB:
    case GP_ERROR_IO_INIT:
    case GP_ERROR_IO_READ:
    case GP_ERROR_IO_WRITE:
    case GP_ERROR_IO_UPDATE:
    case GP_ERROR_IO_SERIAL_SPEED:
    case GP_ERROR_IO_USB_CLEAR_HALT:
      info.cls = ErrorClass::no_comms;
      info.hint = "USB link lost; check the cable and that the camera is on, then reconnect";
      info.retryable = true;
      break;
    case GP_ERROR_UNKNOWN_PORT:
    case GP_ERROR_IO_USB_FIND:
    case GP_ERROR_MODEL_NOT_FOUND:
      info.cls = ErrorClass::not_found;
      info.hint = "no such camera/port; run `gphoto2 --auto-detect` and check the model name in the config";
      break;
    case GP_ERROR_FILE_NOT_FOUND:
    case GP_ERROR_DIRECTORY_NOT_FOUND:
      info.cls = ErrorClass::not_found;
      info.hint = "the file is no longer on the card";
      break;
    case GP_ERROR_CORRUPTED_DATA:
      info.cls = ErrorClass::coms_fail;
      info.hint = "data arrived corrupted over USB; retry, and replace the cable if it repeats";
      info.retryable = true;
      break;
    case GP_ERROR_NO_SPACE:
      info.cls = ErrorClass::needs_operator;
      info.hint = "the memory card is full; free space on it";
      break;
    case GP_ERROR_CAMERA_ERROR:
      info.cls = ErrorClass::device_error;
      info.hint = "the camera reported an error (lens not attached? card missing? Err 99?); check its display";
      break;
    case GP_ERROR_FILE_EXISTS:
    case GP_ERROR_DIRECTORY_EXISTS:
    case GP_ERROR_CANCEL:
      info.cls = ErrorClass::conflict;
      info.hint = "retry the operation";
      info.retryable = true;
      break;
    case GP_ERROR_NO_MEMORY:
    case GP_ERROR_LIBRARY:
    case GP_ERROR_OS_FAILURE:
    case GP_ERROR_HAL:
    case GP_ERROR_FIXED_LIMIT_EXCEEDED:
    case GP_ERROR_PATH_NOT_ABSOLUTE:
      info.cls = ErrorClass::internal;
      info.hint = "libgphoto2 or the OS failed internally; see the log, restart the daemon if it repeats";
      break;
    default:
      info.cls = ErrorClass::hardware_fail;
      info.hint = "unexpected libgphoto2 failure; power-cycle the camera and reconnect";
      info.retryable = true;
  }
  return Error(std::move(info));
}

namespace {

Gphoto2Abilities abilities_on_thread(GPContext* ctx, const std::string& model, CameraAbilities* raw_out) {
  CameraAbilitiesList* list = nullptr;
  check(gp_abilities_list_new(&list), "gp_abilities_list_new");
  struct Free {
    CameraAbilitiesList* l;
    ~Free() { gp_abilities_list_free(l); }
  } free_list{list};
  check(gp_abilities_list_load(list, ctx), "gp_abilities_list_load");
  const int index = gp_abilities_list_lookup_model(list, model.c_str());
  if (index < 0) {
    throw Error(ErrorClass::not_found, "libgphoto2 knows no camera model '" + model + "'",
                "use the exact name from `gphoto2 --list-cameras`, e.g. \"Canon EOS 20D (normal mode)\"");
  }
  CameraAbilities a{};
  check(gp_abilities_list_get_abilities(list, index, &a), "gp_abilities_list_get_abilities");
  if (raw_out) *raw_out = a;
  Gphoto2Abilities out;
  out.model = a.model;
  out.library = a.library;
  out.capture_image = (a.operations & GP_OPERATION_CAPTURE_IMAGE) != 0;
  out.capture_preview = (a.operations & GP_OPERATION_CAPTURE_PREVIEW) != 0;
  out.config = (a.operations & GP_OPERATION_CONFIG) != 0;
  out.experimental = a.status == GP_DRIVER_STATUS_EXPERIMENTAL;
  out.usb_vendor = a.usb_vendor;
  out.usb_product = a.usb_product;
  return out;
}

}  // namespace

Gphoto2Abilities gphoto2_abilities(const std::string& model) {
  return on_gphoto2_thread([&] {
    GPContext* ctx = gp_context_new();
    struct Unref {
      GPContext* c;
      ~Unref() { gp_context_unref(c); }
    } unref{ctx};
    return abilities_on_thread(ctx, model, nullptr);
  });
}

std::vector<DetectedCamera> gphoto2_autodetect() {
  return on_gphoto2_thread([] {
    GPContext* ctx = gp_context_new();
    struct Unref {
      GPContext* c;
      ~Unref() { gp_context_unref(c); }
    } unref{ctx};
    ListGuard list;
    check(gp_camera_autodetect(list.list, ctx), "gp_camera_autodetect");
    std::vector<DetectedCamera> out;
    for (int i = 0; i < gp_list_count(list.list); ++i) {
      const char* name = nullptr;
      const char* value = nullptr;
      gp_list_get_name(list.list, i, &name);
      gp_list_get_value(list.list, i, &value);
      out.push_back({name ? name : "", value ? value : ""});
    }
    return out;
  });
}

// ---------------------------------------------------------------------------------------------

struct Gphoto2Camera::Session {
  GPContext* ctx = nullptr;
  ::Camera* cam = nullptr;
  std::map<std::string, std::vector<std::string>> choices;  // widget name -> labels
  bool has_config = false;
  bool initialized = false;

  ~Session() {
    if (cam && initialized) {
      gp_camera_exit(cam, ctx);
      gp_camera_unref(cam);
    } else if (cam) {
      // libgphoto2 2.5.30's gp_camera_init and gp_camera_set_port_info, failing (no such USB device), leave the
      // camera's private `used` count decremented below zero (an unsigned char: 255), and gp_camera_unref never frees
      // a camera it thinks is in use; gp_camera_free frees regardless (seen by LeakSanitizer, docs/TESTING.md).
      gp_camera_free(cam);
    }
    if (ctx) gp_context_unref(ctx);
  }

  void list_recursive(const std::string& folder, std::vector<CardFile>& out) {
    {
      ListGuard files;
      check(gp_camera_folder_list_files(cam, folder.c_str(), files.list, ctx), "list files in " + folder);
      for (int i = 0; i < gp_list_count(files.list); ++i) {
        const char* name = nullptr;
        gp_list_get_name(files.list, i, &name);
        out.push_back({folder, name});
      }
    }
    ListGuard folders;
    check(gp_camera_folder_list_folders(cam, folder.c_str(), folders.list, ctx), "list folders in " + folder);
    std::vector<std::string> children;
    for (int i = 0; i < gp_list_count(folders.list); ++i) {
      const char* name = nullptr;
      gp_list_get_name(folders.list, i, &name);
      children.push_back((folder == "/" ? "/" : folder + "/") + name);
    }
    for (const auto& c : children) list_recursive(c, out);
  }

  std::vector<std::uint8_t> download(const CardFile& f) {
    FileGuard file;
    check(gp_camera_file_get(cam, f.folder.c_str(), f.name.c_str(), GP_FILE_TYPE_NORMAL, file.file, ctx),
          "download " + f.folder + "/" + f.name);
    const char* data = nullptr;
    unsigned long size = 0;
    check(gp_file_get_data_and_size(file.file, &data, &size), "read downloaded " + f.name);
    return {reinterpret_cast<const std::uint8_t*>(data), reinterpret_cast<const std::uint8_t*>(data) + size};
  }
};

Gphoto2Camera::Gphoto2Camera(Gphoto2Options options)
    : Camera("cam-gphoto2", CameraIdentity{CameraKind::dslr, "", options.model, "", options.port}),
      options_(std::move(options)) {}

Gphoto2Camera::~Gphoto2Camera() { shutdown(); }

namespace {

// Widget labels -> typed limits. Labels that are not numbers ("Auto", "Bulb") are skipped.
CameraLimits limits_from_choices(const std::map<std::string, std::vector<std::string>>& choices) {
  CameraLimits l;
  auto get = [&](const char* n) -> const std::vector<std::string>* {
    auto it = choices.find(n);
    return it == choices.end() ? nullptr : &it->second;
  };
  if (auto* v = get("iso")) {
    for (const auto& s : *v) {
      char* end = nullptr;
      long iso = std::strtol(s.c_str(), &end, 10);
      if (end != s.c_str() && *end == '\0' && iso > 0) l.iso.push_back(static_cast<int>(iso));
    }
  }
  if (auto* v = get("shutterspeed")) {
    for (const auto& s : *v) {
      if (auto t = parse_shutter_label(s)) l.shutter_s.push_back(*t);
    }
  }
  if (auto* v = get("aperture")) {
    for (const auto& s : *v) {
      const char* p = s.c_str();
      if (*p == 'f' || *p == 'F') ++p;
      if (*p == '/') ++p;
      char* end = nullptr;
      double f = std::strtod(p, &end);
      if (end != p && f > 0) l.aperture_f.push_back(f);
    }
  }
  if (auto* v = get("imageformat")) {
    bool raw = false, jpeg = false, both = false;
    for (const auto& s : *v) {
      const bool has_raw = s.find("RAW") != std::string::npos;
      const bool has_jpeg = s.find("JPEG") != std::string::npos;
      raw |= has_raw && !has_jpeg;
      jpeg |= has_jpeg && !has_raw;
      both |= has_raw && has_jpeg;
    }
    if (raw) l.image_formats.push_back(ImageFormat::raw);
    if (jpeg) l.image_formats.push_back(ImageFormat::jpeg);
    if (both) l.image_formats.push_back(ImageFormat::raw_and_jpeg);
  }
  return l;
}

// The camera's label for a typed image format: the largest, finest JPEG where there is a choice.
std::optional<std::string> image_format_label(const std::vector<std::string>& labels, ImageFormat f) {
  std::optional<std::string> best;
  for (const auto& s : labels) {
    const bool has_raw = s.find("RAW") != std::string::npos;
    const bool has_jpeg = s.find("JPEG") != std::string::npos;
    const bool match = (f == ImageFormat::raw && has_raw && !has_jpeg) ||
                       (f == ImageFormat::jpeg && has_jpeg && !has_raw) ||
                       (f == ImageFormat::raw_and_jpeg && has_raw && has_jpeg);
    if (!match) continue;
    const bool large_fine = s.find("Large") != std::string::npos && s.find("Fine") != std::string::npos;
    if (!best || large_fine) best = s;
  }
  return best;
}

}  // namespace

Camera::Connected Gphoto2Camera::do_connect() {
  auto [connected, session] = on_gphoto2_thread_within(options_.call_timeout, "connect", [options = options_] {
    auto s = std::make_shared<Session>();
    s->ctx = gp_context_new();
    check(gp_camera_new(&s->cam), "gp_camera_new");

    std::string model = options.model;
    std::string port = options.port;
    if (model.empty() || port.empty()) {
      ListGuard found;
      check(gp_camera_autodetect(found.list, s->ctx), "gp_camera_autodetect");
      if (gp_list_count(found.list) == 0) {
        throw Error(ErrorInfo{.cls = ErrorClass::no_comms,
                              .message = "no camera detected by libgphoto2",
                              .hint = "connect the camera by USB, switch it on, set Communication to normal mode",
                              .retryable = true});
      }
      const char* name = nullptr;
      const char* value = nullptr;
      gp_list_get_name(found.list, 0, &name);
      gp_list_get_value(found.list, 0, &value);
      if (model.empty()) model = name;
      if (port.empty()) port = value;
    }

    CameraAbilities abilities{};
    abilities_on_thread(s->ctx, model, &abilities);
    check(gp_camera_set_abilities(s->cam, abilities), "gp_camera_set_abilities");

    GPPortInfoList* ports = nullptr;
    check(gp_port_info_list_new(&ports), "gp_port_info_list_new");
    struct FreePorts {
      GPPortInfoList* p;
      ~FreePorts() { gp_port_info_list_free(p); }
    } free_ports{ports};
    check(gp_port_info_list_load(ports), "gp_port_info_list_load");
    const int port_index = gp_port_info_list_lookup_path(ports, port.c_str());
    if (port_index < 0) throw gphoto2_error(port_index, "look up port " + port);
    GPPortInfo info;
    check(gp_port_info_list_get_info(ports, port_index, &info), "gp_port_info_list_get_info");
    check(gp_camera_set_port_info(s->cam, info), "gp_camera_set_port_info");
    check(gp_camera_init(s->cam, s->ctx), "init " + model + " on " + port);
    s->initialized = true;

    // Cameras without configuration (Directory Browse) answer NOT_SUPPORTED: no settings then.
    WidgetGuard window;
    CameraSettings current;
    if (gp_camera_get_config(s->cam, &window.w, s->ctx) == GP_OK) {
      s->has_config = true;
      for (const char* name : {"iso", "shutterspeed", "aperture", "imageformat"}) {
        CameraWidget* w = nullptr;
        if (gp_widget_get_child_by_name(window.w, name, &w) != GP_OK) continue;
        auto& labels = s->choices[name];
        for (int i = 0; i < gp_widget_count_choices(w); ++i) {
          const char* label = nullptr;
          if (gp_widget_get_choice(w, i, &label) == GP_OK && label) labels.emplace_back(label);
        }
        const char* value = nullptr;
        if (gp_widget_get_value(w, &value) != GP_OK || !value) continue;
        const std::string v = value;
        if (std::string(name) == "iso") {
          if (int iso = std::atoi(v.c_str()); iso > 0) current.iso = iso;
        } else if (std::string(name) == "shutterspeed") {
          current.shutter_s = parse_shutter_label(v);
        } else if (std::string(name) == "aperture") {
          if (double f = std::strtod(v.c_str(), nullptr); f > 0) current.aperture_f = f;
        }
      }
    }

    Connected c;
    c.identity = CameraIdentity{CameraKind::dslr, "", abilities.model, "", port};
    if (auto space = c.identity.model.find(' '); space != std::string::npos) {
      c.identity.make = c.identity.model.substr(0, space);
      c.identity.model = c.identity.model.substr(space + 1);
    }
    CameraText summary;
    if (gp_camera_get_summary(s->cam, &summary, s->ctx) == GP_OK) {
      // Serial numbers appear as "Serial Number: ..." in most camlibs' summaries.
      const std::string text = summary.text;
      if (auto at = text.find("Serial Number:"); at != std::string::npos) {
        auto end = text.find('\n', at);
        std::string serial = text.substr(at + 14, end == std::string::npos ? std::string::npos : end - at - 14);
        serial.erase(0, serial.find_first_not_of(' '));
        c.identity.serial = serial;
      }
    }
    c.limits = limits_from_choices(s->choices);
    c.settings = current;
    return std::make_pair(std::move(c), std::move(s));
  });
  session_ = std::move(session);
  return connected;
}

void Gphoto2Camera::do_disconnect() noexcept {
  if (!session_) return;
  // Closed on the gphoto2 thread, without waiting: behind a stuck call this must not block.
  gphoto2_thread().post([s = std::move(session_)]() mutable { s.reset(); });
}

void Gphoto2Camera::do_configure(const CameraSettings& wanted) {
  on_gphoto2_thread_within(options_.call_timeout, "configure", [session = session_, wanted] {
    Session& s = *session;
    WidgetGuard window;
    check(gp_camera_get_config(s.cam, &window.w, s.ctx), "read configuration");
    auto set = [&](const char* name, const std::string& label) {
      CameraWidget* w = nullptr;
      check(gp_widget_get_child_by_name(window.w, name, &w), std::string("find widget ") + name);
      check(gp_widget_set_value(w, label.c_str()), std::string("set ") + name + " to " + label);
    };
    // Find the camera's own label for each typed value so that "1/60" is sent exactly as listed.
    auto label_for = [&](const char* name, double value, auto parse) -> std::string {
      for (const auto& l : s.choices[name]) {
        if (auto v = parse(l); v && std::abs(*v - value) <= 0.01 * std::abs(*v)) return l;
      }
      throw Error(ErrorClass::bad_parameter, std::string("no ") + name + " choice matches the requested value",
                  "see limits()");
    };
    auto number = [](const std::string& l) -> std::optional<double> {
      const char* p = l.c_str();
      if (*p == 'f' || *p == 'F') ++p;
      if (*p == '/') ++p;
      char* end = nullptr;
      double v = std::strtod(p, &end);
      if (end == p) return std::nullopt;
      return v;
    };
    if (wanted.iso) set("iso", label_for("iso", *wanted.iso, number));
    if (wanted.shutter_s) set("shutterspeed", label_for("shutterspeed", *wanted.shutter_s, parse_shutter_label));
    if (wanted.aperture_f) set("aperture", label_for("aperture", *wanted.aperture_f, number));
    if (wanted.image_format) {
      auto label = image_format_label(s.choices["imageformat"], *wanted.image_format);
      if (!label) throw Error(ErrorClass::bad_parameter, "no imageformat choice for the requested format", "");
      set("imageformat", *label);
    }
    check(gp_camera_set_config(s.cam, window.w, s.ctx), "write configuration");
  });
}

std::future<std::vector<CardFile>> Gphoto2Camera::list_files(std::string folder) {
  return worker().submit([this, folder] {
    require_connected();
    return on_gphoto2_thread_within(options_.call_timeout, "list files", [session = session_, folder] {
      std::vector<CardFile> out;
      session->list_recursive(folder, out);
      return out;
    });
  });
}

std::future<std::vector<std::uint8_t>> Gphoto2Camera::download(CardFile file) {
  return worker().submit([this, file] {
    require_connected();
    return on_gphoto2_thread_within(options_.call_timeout, "download " + file.name,
                                    [session = session_, file] { return session->download(file); });
  });
}

std::future<void> Gphoto2Camera::remove(CardFile file) {
  return worker().submit([this, file] {
    require_connected();
    on_gphoto2_thread_within(options_.call_timeout, "delete " + file.name, [session = session_, file] {
      check(gp_camera_file_delete(session->cam, file.folder.c_str(), file.name.c_str(), session->ctx),
            "delete " + file.folder + "/" + file.name);
    });
  });
}

CapturedFrame Gphoto2Camera::do_capture_frame(std::size_t index) {
  const auto format = settings().image_format.value_or(ImageFormat::raw);
  // Kept as laid out by hand: the lambda's body indented from the statement, as in the other gphoto2 calls.
  // clang-format off
  return on_gphoto2_thread_within(options_.call_timeout, "capture frame " + std::to_string(index),
                                  [session = session_, options = options_, format, index] {
    Session& s = *session;
    CameraFilePath shot{};
    check(gp_camera_capture(s.cam, GP_CAPTURE_IMAGE, &shot, s.ctx), "capture frame " + std::to_string(index));
    CapturedFrame frame;
    frame.timestamp = std::chrono::system_clock::now();
    std::vector<CardFile> files{{shot.folder, shot.name}};

    // capture() names one file; with RAW+JPEG the partner arrives as a FILE_ADDED event.
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::milliseconds(format == ImageFormat::raw_and_jpeg ? options.pair_wait_ms : 0);
    while (format == ImageFormat::raw_and_jpeg && files.size() < 2 && std::chrono::steady_clock::now() < deadline) {
      CameraEventType type{};
      void* data = nullptr;
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      const int rc = gp_camera_wait_for_event(s.cam, static_cast<int>(std::max<long>(1, left.count())), &type, &data, s.ctx);
      if (rc < GP_OK) break;  // camlibs without events: fall back to the single file
      if (type == GP_EVENT_FILE_ADDED && data) {
        auto* p = static_cast<CameraFilePath*>(data);
        if (basename_without_extension(p->name) == basename_without_extension(shot.name)) {
          files.push_back({p->folder, p->name});
        }
      }
      std::free(data);
      if (type == GP_EVENT_TIMEOUT) break;
    }

    if (format == ImageFormat::raw_and_jpeg && files.size() < 2) {
      // No FILE_ADDED for the partner (camlibs without events): look for the same basename.
      ListGuard listing;
      if (gp_camera_folder_list_files(s.cam, shot.folder, listing.list, s.ctx) >= GP_OK) {
        for (int i = 0; i < gp_list_count(listing.list); ++i) {
          const char* other = nullptr;
          gp_list_get_name(listing.list, i, &other);
          if (other && std::string(other) != shot.name &&
              basename_without_extension(other) == basename_without_extension(shot.name)) {
            files.push_back({shot.folder, other});
          }
        }
      }
    }

    for (const auto& f : files) {
      auto bytes = s.download(f);
      if (!options.keep_dir.empty()) {
        std::filesystem::create_directories(options.keep_dir);
        const auto path = options.keep_dir / f.name;
        std::ofstream out(path, std::ios::binary);
        out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
        if (!out) throw Error(ErrorClass::io_error, "cannot save " + path.string(), "check disk space and permissions");
        frame.saved_files.push_back(path);
      }
      if (is_raw_file_name(f.name) && frame.file_bytes.empty()) {
        frame.file_bytes = std::move(bytes);
        frame.file_name = f.name;
      }
      if (options.delete_on_card) {
        check(gp_camera_file_delete(s.cam, f.folder.c_str(), f.name.c_str(), s.ctx), "delete " + f.name + " on card");
      }
    }
    if (frame.file_bytes.empty()) {
      throw Error(ErrorClass::unsupported, "capture produced no raw file (got " + files.front().name + ")",
                  "set the camera's image format to RAW or RAW + JPEG; JPEG alone has no sensor counts");
    }
    return frame;
  });
  // clang-format on
}

}  // namespace colorlab::drivers::camera
