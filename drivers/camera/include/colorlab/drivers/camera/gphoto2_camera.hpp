#pragma once
// Tethered DSLR through libgphoto2 (the lab's Canon EOS 20D in "normal mode", canon camlib).
//
// libgphoto2 keeps global state and is not thread-safe, so every libgphoto2 call in the process,
// from every Gphoto2Camera and from the free functions below, runs on one dedicated thread in
// the C locale (choice labels pass through gettext). Settings are looked up by widget name
// (`iso`, `shutterspeed`, `aperture`, `imageformat`) and written in a single set_config, because
// single-setting writes fall back to a full config round trip per setting on older camlibs.
// Each capture downloads the raw (and its JPEG partner, paired by basename from FILE_ADDED
// events) and deletes them from the card, since the canon camlib's capture cost grows with the
// number of files on the card.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <future>
#include <string>
#include <string_view>
#include <vector>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/camera.hpp"

namespace colorlab::drivers::camera {

// libgphoto2 result code (GP_ERROR_*) -> typed error naming the operation.
Error gphoto2_error(int code, std::string_view operation);

struct Gphoto2Abilities {
  std::string model;
  std::string library;  // camlib file, e.g. ".../canon.so"
  bool capture_image = false;
  bool capture_preview = false;
  bool config = false;
  bool experimental = false;  // driver status CAP_EXP / GP_DRIVER_STATUS_EXPERIMENTAL
  int usb_vendor = 0;
  int usb_product = 0;
};

// Abilities from libgphoto2's model table; Error(not_found) for an unknown model.
Gphoto2Abilities gphoto2_abilities(const std::string& model);

struct DetectedCamera {
  std::string model;
  std::string port;
};
std::vector<DetectedCamera> gphoto2_autodetect();

struct Gphoto2Options {
  std::string model = "Canon EOS 20D (normal mode)";  // empty: first autodetected camera
  std::string port;                                   // empty: autodetect; "usb:001,005"; "disk:/dir"
  std::filesystem::path keep_dir;                     // downloaded raw + JPEG are saved here; empty: memory only
  bool delete_on_card = true;
  int pair_wait_ms = 3000;  // how long to wait for the JPEG partner of a RAW+JPEG capture
  // Longest a single libgphoto2 call may take (Canon captures take 4-15 s; init a few s) before
  // the camera is declared stuck: Error(hardware_fail), camera in fault state.
  std::chrono::milliseconds call_timeout{60'000};
};

struct CardFile {
  std::string folder;
  std::string name;
  friend bool operator==(const CardFile&, const CardFile&) = default;
};

class Gphoto2Camera final : public Camera {
 public:
  explicit Gphoto2Camera(Gphoto2Options options);
  ~Gphoto2Camera() override;

  // Card access (also what the Directory Browse camlib offers without a camera).
  std::future<std::vector<CardFile>> list_files(std::string folder = "/");  // recursive
  std::future<std::vector<std::uint8_t>> download(CardFile file);
  std::future<void> remove(CardFile file);

 protected:
  Connected do_connect() override;
  void do_disconnect() noexcept override;
  void do_configure(const CameraSettings& settings) override;
  CapturedFrame do_capture_frame(std::size_t index) override;

 private:
  struct Session;
  Gphoto2Options options_;
  // Owned jointly with in-flight libgphoto2 calls; always released on the gphoto2 thread.
  std::shared_ptr<Session> session_;
};

// Raw file extensions LibRaw can decode, upper case without dot (CR2, DNG, ...).
bool is_raw_file_name(std::string_view name);

}  // namespace colorlab::drivers::camera
