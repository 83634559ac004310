#pragma once
// One interface for every camera colorlab drives: a tethered DSLR (libgphoto2 + LibRaw), a
// GenICam machine-vision camera (Aravis) and the simulated DSLR (real DNG files through the same
// LibRaw path).
//
// The public API is non-virtual (libcamera's PipelineHandler pattern): it checks state, posts the
// work to a worker thread the camera owns and returns at once with a future, or calls back when
// done. Drivers implement only the protected do_* hooks, which always run on that worker thread,
// so a driver never needs its own locking and a non-thread-safe library sees exactly one thread.
//
// State machine (the function behind each transition in brackets):
//
//   disconnected --[connect/reconnect]--> initialising --ok--> ready --[capture]--> busy
//        ^  ^                                  |                 ^  ^                 |
//        |  +------------- error --------------+                 |  +-- done, timeout,-+
//        |                                                       |      busy, bad data  |
//        +------------- [disconnect], or no_comms in a series/configure -----------------+
//   fault <-- hardware, protocol or internal error in a series/configure (after_failure);
//             left only through [connect] or [reconnect].
//
// A capture series streams: frame k is decoded and handed to the sink while frame k+1 is being
// captured (FramePipeline). A series that stops early is reported with `delivered < requested`
// and the typed error that stopped it, never as complete.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/camera_settings.hpp"
#include "colorlab/drivers/camera/frame_pipeline.hpp"
#include "colorlab/drivers/camera/raw_image.hpp"
#include "colorlab/drivers/camera/worker_thread.hpp"

namespace colorlab::drivers::camera {

enum class CameraKind {
  dslr,
  genicam,
  simulated
};
enum class CameraState {
  disconnected,
  initialising,
  ready,
  busy,
  fault
};

std::string_view to_string(CameraKind k);
std::string_view to_string(CameraState s);

struct CameraIdentity {
  CameraKind kind = CameraKind::simulated;
  std::string make;
  std::string model;
  std::string serial;
  std::string port;  // "usb:001,005", "127.0.0.1", a capture directory, ...
};

// What the capture stage hands to the decode stage: either an encoded raw file (DSLR: CR2, DNG)
// that LibRaw decodes, or counts that arrived already as pixels (GenICam).
struct CapturedFrame {
  std::chrono::system_clock::time_point timestamp{};
  std::string file_name;
  std::vector<std::uint8_t> file_bytes;
  std::optional<OwnedRawImage> pixels;
  std::vector<std::filesystem::path> saved_files;  // raw and sidecars kept on disk, if any
};

struct CaptureOptions {
  std::size_t queue_depth = 2;  // frames captured ahead of the decoder
};

struct CaptureReport {
  std::size_t requested = 0;
  std::size_t delivered = 0;   // frames the sink accepted
  std::optional<Error> error;  // why the series stopped early (or the sink's failure)
  std::vector<std::filesystem::path> saved_files;
  std::chrono::nanoseconds capture_time{0};  // summed over frames, capture stage
  std::chrono::nanoseconds decode_time{0};   // summed over frames, decode + sink
  std::chrono::nanoseconds wall_time{0};

  bool complete() const { return !error && delivered == requested; }
};

// Called on the camera's decode thread, once per frame, in frame order. The image is a view valid
// only during the call. Throwing stops the series (the report carries the error).
using FrameSink = std::function<void(const RawImage&)>;
using CaptureDone = std::function<void(CaptureReport)>;
// Completion of connect/configure: nullopt on success.
using OperationDone = std::function<void(std::optional<Error>)>;

class Camera {
 public:
  virtual ~Camera();
  Camera(const Camera&) = delete;
  Camera& operator=(const Camera&) = delete;

  // Opens the device and reads identity and limits. The future throws colorlab::Error.
  std::future<void> connect();
  std::future<void> disconnect();
  // The reconnect state machine: close, back off (doubling from `first_backoff`), reopen, and
  // re-verify identity: a different serial than before is Error(needs_operator), because
  // calibration and defect maps belong to one camera body. Settings configured earlier are
  // applied again (a rebooted camera forgets them). Gives up after `attempts` tries with the
  // last error. connect(), by contrast, starts from whatever the device reports.
  std::future<void> reconnect(int attempts = 5,
                              std::chrono::milliseconds first_backoff = std::chrono::milliseconds(200));
  // Validates against limits() first: Error(unsupported) / Error(bad_parameter) with a hint.
  std::future<void> configure(CameraSettings settings);
  // Callback forms for event loops (asio_camera.hpp wraps them for co_await); `done` runs on
  // the camera's worker thread, or on the caller's when refused at once.
  void connect(OperationDone done);
  void configure(CameraSettings settings, OperationDone done);

  // Never throws: every failure is in the report. Error(conflict) at once if a series runs.
  std::future<CaptureReport> capture(std::size_t n_frames, FrameSink sink, CaptureOptions options = {});
  // Same, with `done` called on the camera's worker thread (post it to your executor from there).
  void capture(std::size_t n_frames, FrameSink sink, CaptureDone done, CaptureOptions options = {});

  CameraState state() const { return state_.load(); }
  CameraIdentity identity() const;
  CameraLimits limits() const;
  CameraSettings settings() const;
  std::string name() const;  // "Canon EOS 20D #123" for messages

 protected:
  struct Connected {
    CameraIdentity identity;
    CameraLimits limits;
    CameraSettings settings;  // as read back from the device
  };

  explicit Camera(std::string worker_name, CameraIdentity provisional);

  // Derived destructors must call this first, so no hook runs on a half-destroyed object.
  void shutdown();

  virtual Connected do_connect() = 0;
  virtual void do_disconnect() noexcept = 0;
  virtual void do_configure(const CameraSettings& settings) = 0;
  virtual void do_begin_series(std::size_t /*n_frames*/) {}
  virtual CapturedFrame do_capture_frame(std::size_t index) = 0;
  virtual void do_end_series() noexcept {}

  // For drivers that run extra device calls (file listing, downloads) on the same worker.
  WorkerThread& worker() { return *worker_; }
  void require_connected() const;  // throws Error(no_comms)
  void set_state(CameraState s) { state_.store(s); }
  // Adds a line to the bounded event transcript attached to every error this camera reports.
  void note(std::string line);
  std::vector<std::string> transcript() const;

 private:
  CaptureReport run_series(std::size_t n, const FrameSink& sink, std::size_t depth);
  void deliver(CapturedFrame&& frame, std::size_t index, const FrameSink& sink);
  void after_failure(const Error& e);
  Error with_transcript(const Error& e) const;

  mutable std::mutex mutex_;
  CameraIdentity identity_;
  CameraLimits limits_;
  CameraSettings settings_;
  CameraSettings configured_;  // what callers asked for since connect(); reapplied by reconnect()
  std::atomic<CameraState> state_{CameraState::disconnected};
  std::atomic<bool> series_pending_{false};
  std::deque<std::string> transcript_;  // guarded by mutex_
  std::chrono::steady_clock::time_point created_ = std::chrono::steady_clock::now();
  std::unique_ptr<FramePipeline<CapturedFrame>> pipeline_;
  std::unique_ptr<WorkerThread> worker_;  // declared last: joined first
};

}  // namespace colorlab::drivers::camera
