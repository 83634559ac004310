#pragma once
// The simulated lab's configuration (TOML; see docs/simulator.md). Every field has a default,
// so an empty file, or none, gives the default lab with every instrument.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/sim/camera/camera_model.hpp"
#include "colorlab/sim/dmx_sim.hpp"
#include "colorlab/sim/spectrolino_model.hpp"
#include "colorlab/verify/cabinet.hpp"

namespace colorlab::sim {

struct Ls110SimConfig {
  bool enabled = true;
  std::string id = "ls110";
  int aim_row = 0;  // floor grid spot the meter is aimed at (row 0 = front)
  int aim_col = 9;
  nlohmann::json faults = nlohmann::json::object();
};

struct SpectrolinoLabConfig {
  bool enabled = true;
  std::string id = "spectrolino";
  SpectrolinoConfig device;
  std::optional<std::pair<double, double>> head_mm;  // initial head position (default: home, or the tile
                                                     // for a stand-alone Spectrolino)
  nlohmann::json faults = nlohmann::json::object();
};

struct DmxLabConfig {
  bool enabled = true;
  std::string id = "dmx";
  DmxConfig device;
  nlohmann::json faults = nlohmann::json::object();
};

// The GenICam camera: Aravis's GigE Vision fake on loopback, filled by the scene's camera model.
struct GenicamLabConfig {
  bool enabled = true;
  std::string id = "genicam";
  std::string address = "127.0.0.1";
  std::string serial = "CLGV0001";
  int width = 3504;
  int height = 2336;
};

// The tethered DSLR: an EOS 20D-like body rendered by the scene's camera model, writing DNG (and JPEG /
// TIFF) files and serving the tethered-camera protocol on a Unix socket.
struct DslrLabConfig {
  bool enabled = true;
  std::string id = "dslr";
  std::string serial = "SIM20D0001";
  int width = 3504;
  int height = 2336;
  // The chart's pose in front of the camera: seeded (random_chart_pose of pose_seed), square, or given.
  enum class Pose {
    seeded,
    square,
    given
  } pose = Pose::seeded;
  std::optional<std::uint64_t> pose_seed;  // default: derived from the lab seed
  camera::ChartPose given_pose;
  std::optional<std::filesystem::path> socket;       // default: beside the control socket
  std::optional<std::filesystem::path> capture_dir;  // default: <scratch_dir>/colorlab-sim-<pid>-dslr, removed at exit
  double transfer_s = 1.2;                           // card write + USB transfer of the raw (simulated s)
  nlohmann::json faults = nlohmann::json::object();
};

// The dcttech USB relay board switching the lamps, on a Unix socket carrying HID feature reports.
// Off by default: the default lab switches its lamps through the DMX widget.
struct RelayLabConfig {
  bool enabled = false;
  std::string id = "relay";
  std::string board_id = "CLRLB";  // 5 characters
  int relays = 8;                  // USBRelay1..8
  std::vector<std::pair<std::string, int>> lamps{{"D65", 1}, {"TL84", 2}, {"CWF", 3}, {"A", 4}, {"UV", 5}};
  std::optional<std::filesystem::path> socket;  // default: beside the control socket
  nlohmann::json faults = nlohmann::json::object();
};

struct LabConfig {
  std::uint64_t seed = 1;
  double time_scale = 1.0;
  std::vector<std::string> lamps_on{"D65"};
  double dimmer_percent = 100.0;
  std::optional<std::filesystem::path> chart_file;
  // [scene] floor_field: "section-6.2" (default, the dissertation's measured shape) or "geometric" (the
  // [cabinet]'s emitters light the floor by their form factor; docs/verify.md, "The measured scene").
  bool geometric_floor = false;
  verify::CabinetGeometry cabinet = verify::default_cabinet();  // [cabinet]
  std::optional<std::filesystem::path> control_socket;          // default: a fresh path under $XDG_RUNTIME_DIR or /tmp
  // Where the DSLR's default card folder goes (colorlab-sim --scratch-dir; colorlabd passes <state_dir>/sim):
  // default the temporary directory. Killed simulators' folders there are reclaimed at start.
  std::optional<std::filesystem::path> scratch_dir;
  Ls110SimConfig ls110;
  SpectrolinoLabConfig spectrolino;
  DmxLabConfig dmx;
  GenicamLabConfig genicam;
  DslrLabConfig dslr;
  RelayLabConfig relay;
};

// Throws Error{bad_parameter} naming file, line and key.
LabConfig load_lab_config(const std::filesystem::path& file);

}  // namespace colorlab::sim
