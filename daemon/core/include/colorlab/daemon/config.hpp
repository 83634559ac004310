#pragma once
// colorlabd's configuration: a TOML file (see docs/configuration.md), or the embedded default
// that starts the simulated lab. Command-line flags override both.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "colorlab/drivers/factory.hpp"
#include "colorlab/verify/cabinet.hpp"
#include "colorlab/verify/lens_calibration.hpp"

namespace colorlab::daemon {

struct SimulatorConfig {
  bool enabled = false;                         // start colorlab-sim as a child process
  std::optional<std::filesystem::path> config;  // its TOML; none = the default lab
  std::optional<double> time_scale;
  std::optional<std::uint64_t> seed;
  int nice = 0;  // nice steps the child runs below colorlabd: colorlabd copies [priority] simulator_nice here
};

// [priority]: CPU priority of the heavy work beside the threads that answer (docs/configuration.md,
// "CPU priority"; core/thread_priority.hpp). Nice steps below colorlabd's own; 0 = the same.
struct PriorityConfig {
  int heavy_work_nice = 0;  // worker pool (fits, analyses), RAW decoding, reports, the blob check
  int simulator_nice = 0;   // the embedded simulated lab: a real lab's instruments have their own processors
};

// [campaigns]: where the lab's own scripts live, and how executions survive restarts.
struct CampaignConfig {
  // default: <state_dir>/campaigns
  std::optional<std::filesystem::path> directory;
  int max_resume_attempts = 3;  // restarts in a row without a committed step before the crash-loop guard trips
  // The guard suspends the execution and retries it itself after a back-off that doubles from
  // crash_loop_backoff_s up to crash_loop_backoff_max_s (the daemon's own seconds, not lab seconds), at
  // most crash_loop_retries times; a crash after the last retry ends the run (its queue item's on_failure).
  double crash_loop_backoff_s = 60;
  double crash_loop_backoff_max_s = 1800;
  int crash_loop_retries = 6;
  bool lamps_off_at_shutdown = false;
  double lamp_warmup_s = 900;         // after relighting on resume, when there is no luminance meter
  double stable_tolerance_pct = 0.5;  // lamp stability on resume: drift over the window (LS-110)
  double stable_window_s = 60;
  double stable_interval_s = 5;
  double stable_timeout_s = 1800;
  // Suspend, not fail (lab seconds): check a stopping condition every retry_s, go on once it has
  // stayed clear for settle_s, give up after max_s.
  double suspend_retry_s = 30;
  double suspend_settle_s = 60;
  double suspend_max_s = 8 * 3600;
  double time_scale = 1;  // lab seconds per wall second for an external simulated lab
};

// [queue]: the night's queue (docs/campaigns.md, "A night's queue").
struct QueueConfig {
  bool autostart = false;  // start the queue with the daemon (unless a failed item halted it)
};

// [notify]: who hears of a suspension, a crash loop or a failed run (docs/configuration.md, "Notifications").
struct NotifyConfig {
  std::vector<std::string> command;  // argv, run without a shell; the notification's JSON on its stdin
  std::string webhook;               // http:// or https:// URL the JSON is POSTed to
  double timeout_s = 10;             // per delivery: a command still running then is killed
  std::vector<std::string> events = {"suspended", "crash-loop", "failed"};
  bool enabled() const { return !command.empty() || !webhook.empty(); }
};

// [access]: who may do what over the API (docs/API.md, "Access"), TLS for a listener beyond
// loopback, and how long the control lock lasts without being renewed.
struct AccessConfig {
  std::string loopback_scope = "read";  // what loopback TCP may do without a key: read | control | admin
  bool allow_plaintext = false;         // a listener beyond loopback without TLS (then warned about)
  // PEM; with tls_private_key, TCP speaks TLS
  std::optional<std::filesystem::path> tls_certificate;
  std::optional<std::filesystem::path> tls_private_key;
  double control_lease_s = 600;
};

// [blobs]: the image store under <state_dir>/blobs (docs/configuration.md).
struct BlobConfig {
  double retention_days = 0;      // 0: blobs are kept for ever
  std::vector<std::string> keep;  // kinds retention never removes ("raw", "average", …)
  bool verify_hashes = true;      // the start-up check hashes every file (false: sizes only)
  // Set when the TOML has a [ship] section (colorlab-ship's, docs/fleet.md): retention then keeps every blob of a
  // run that has not shipped yet, by the position the agent notes in <state_dir>/ship/shipped-position.
  bool keep_unshipped = false;
};

// [api]: how the HTTP API serves (docs/configuration.md).
struct ApiConfig {
  unsigned threads = 2;                // HTTP pool threads serving stored data (runs, blobs, the event log)
  double stream_write_timeout_s = 10;  // a live event stream whose client stalls this long is dropped
  unsigned max_connections = 1024;
};

struct DaemonConfig {
  std::filesystem::path state_dir = "./colorlab-state";
  std::string listen_host = "127.0.0.1";
  unsigned short listen_port = 8765;
  std::optional<std::filesystem::path> unix_socket;  // default: <state_dir>/colorlabd.sock
  std::vector<drivers::InstrumentConfig> instruments;
  SimulatorConfig simulator;
  CampaignConfig campaigns;
  QueueConfig queue;
  NotifyConfig notify;
  ApiConfig api;
  PriorityConfig priority;
  BlobConfig blobs;
  AccessConfig access;
  // The light cabinet's geometry ([cabinet], docs/verify.md "The cabinet in the lab configuration"), validated when
  // the file is read and served at GET /v1/lab/cabinet, so `colorlab scene` gets the lab's box without --lab.
  // Absent: the built-in cabinet.
  std::optional<verify::CabinetGeometry> cabinet;
  // The lab's lens calibrations ([[lens]], docs/verify.md "The lens calibration"), served at GET /v1/lab/lenses.
  std::vector<verify::LensCalibration> lenses;

  std::filesystem::path database_path() const;
  std::filesystem::path socket_path() const;
  std::filesystem::path campaign_dir() const;
};

// The configuration colorlabd uses without --config: the simulated lab, state under ./colorlab-state.
DaemonConfig embedded_default_config();
// Throws Error{bad_parameter} naming the file, line and key for anything invalid.
DaemonConfig load_config(const std::filesystem::path& file);
// The same from text read from `file` (which only names it in errors and anchors relative paths).
DaemonConfig parse_config(std::string_view text, const std::filesystem::path& file);
// "HOST:PORT" → host and port; throws Error{bad_parameter}.
void apply_listen(DaemonConfig& c, const std::string& host_port);

}  // namespace colorlab::daemon
