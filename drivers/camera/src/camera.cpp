#include "colorlab/drivers/camera/camera.hpp"

#include <algorithm>
#include <exception>
#include <thread>
#include <utility>

#include "colorlab/core/log.hpp"
#include "colorlab/drivers/camera/raw_decoder.hpp"

namespace colorlab::drivers::camera {

std::string_view to_string(CameraKind k) {
  switch (k) {
    case CameraKind::dslr: return "dslr";
    case CameraKind::genicam: return "genicam";
    case CameraKind::simulated: return "simulated";
  }
  return "?";
}

std::string_view to_string(CameraState s) {
  switch (s) {
    case CameraState::disconnected: return "disconnected";
    case CameraState::initialising: return "initialising";
    case CameraState::ready: return "ready";
    case CameraState::busy: return "busy";
    case CameraState::fault: return "fault";
  }
  return "?";
}

namespace {

// Anything a driver lets escape that is not a colorlab::Error is a bug, but the daemon must
// still get a typed error rather than a terminate().
Error to_error(std::exception_ptr p, std::string_view where) {
  try {
    std::rethrow_exception(p);
  } catch (const Error& e) {
    return e;
  } catch (const std::exception& e) {
    return Error(ErrorClass::internal, std::string(where) + ": " + e.what(), "report this as a bug");
  } catch (...) {
    return Error(ErrorClass::internal, std::string(where) + ": unknown exception", "report this as a bug");
  }
}

}  // namespace

Camera::Camera(std::string worker_name, CameraIdentity provisional)
    : identity_(std::move(provisional)),
      pipeline_(std::make_unique<FramePipeline<CapturedFrame>>(2)),
      worker_(std::make_unique<WorkerThread>(std::move(worker_name))) {}

Camera::~Camera() {
  if (worker_) {
    log::error("camera", "Camera subclass did not call shutdown() in its destructor");
    worker_.reset();
  }
}

void Camera::shutdown() {
  if (!worker_) return;
  worker_
      ->submit([this] {
        if (state_.load() != CameraState::disconnected) do_disconnect();
        state_.store(CameraState::disconnected);
      })
      .wait();
  worker_.reset();
  pipeline_.reset();
}

CameraIdentity Camera::identity() const {
  std::lock_guard lock(mutex_);
  return identity_;
}

CameraLimits Camera::limits() const {
  std::lock_guard lock(mutex_);
  return limits_;
}

CameraSettings Camera::settings() const {
  std::lock_guard lock(mutex_);
  return settings_;
}

std::string Camera::name() const {
  std::lock_guard lock(mutex_);
  std::string n = identity_.make.empty() ? std::string(to_string(identity_.kind)) + " camera"
                                         : identity_.make + " " + identity_.model;
  if (!identity_.serial.empty()) n += " #" + identity_.serial;
  return n;
}

void Camera::note(std::string line) {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - created_);
  std::lock_guard lock(mutex_);
  transcript_.push_back("+" + std::to_string(ms.count()) + "ms " + std::move(line));
  constexpr std::size_t kCapacity = 32;  // enough for a series' last frames and the failure
  while (transcript_.size() > kCapacity) transcript_.pop_front();
}

std::vector<std::string> Camera::transcript() const {
  std::lock_guard lock(mutex_);
  return {transcript_.begin(), transcript_.end()};
}

Error Camera::with_transcript(const Error& e) const {
  ErrorInfo info = e.info();
  if (info.transcript.empty()) info.transcript = transcript();
  return Error(std::move(info));
}

void Camera::require_connected() const {
  const auto s = state_.load();
  if (s == CameraState::disconnected || s == CameraState::initialising) {
    throw Error(ErrorInfo{.cls = ErrorClass::no_comms,
                          .message = name() + " is not connected",
                          .hint = "connect() the camera first; check the cable/network and power",
                          .retryable = true});
  }
  if (s == CameraState::fault) {
    throw Error(ErrorInfo{.cls = ErrorClass::hardware_fail,
                          .message = name() + " is in fault state after an earlier error",
                          .hint = "reconnect (disconnect, then connect) to recover",
                          .retryable = true});
  }
}

std::future<void> Camera::connect() {
  return worker_->submit([this] {
    if (state_.load() != CameraState::disconnected) do_disconnect();
    state_.store(CameraState::initialising);
    try {
      Connected c = do_connect();
      {
        std::lock_guard lock(mutex_);
        identity_ = std::move(c.identity);
        limits_ = std::move(c.limits);
        settings_ = std::move(c.settings);
        configured_ = {};
      }
      state_.store(CameraState::ready);
      note("connected " + name());
      log::info("camera", "connected " + name());
    } catch (...) {
      state_.store(CameraState::disconnected);
      Error e = to_error(std::current_exception(), "connect " + name());
      note(std::string("connect failed: ") + e.what());
      throw with_transcript(e);
    }
  });
}

std::future<void> Camera::reconnect(int attempts, std::chrono::milliseconds first_backoff) {
  return worker_->submit([this, attempts, first_backoff] {
    const std::string expected_serial = identity().serial;
    auto backoff = first_backoff;
    std::optional<Error> last;
    for (int attempt = 1; attempt <= std::max(1, attempts); ++attempt) {
      if (state_.load() != CameraState::disconnected) do_disconnect();
      state_.store(CameraState::disconnected);
      if (attempt > 1) {
        std::this_thread::sleep_for(backoff);
        backoff *= 2;
      }
      note("reconnect attempt " + std::to_string(attempt));
      state_.store(CameraState::initialising);
      try {
        Connected c = do_connect();
        if (!expected_serial.empty() && c.identity.serial != expected_serial) {
          do_disconnect();
          state_.store(CameraState::disconnected);
          throw with_transcript(Error(ErrorInfo{
              .cls = ErrorClass::needs_operator,
              .message = "reconnected to camera #" + c.identity.serial + ", expected #" + expected_serial,
              .hint = "a different camera body is attached; put the original back or start a new calibration",
          }));
        }
        const CameraSettings again = [&] {
          std::lock_guard lock(mutex_);
          identity_ = std::move(c.identity);
          limits_ = std::move(c.limits);
          settings_ = std::move(c.settings);
          return configured_;
        }();
        do_configure(again);
        {
          std::lock_guard lock(mutex_);
          settings_.merge(again);
        }
        state_.store(CameraState::ready);
        note("reconnected " + name());
        return;
      } catch (const Error& e) {
        if (e.cls() == ErrorClass::needs_operator) throw;
        state_.store(CameraState::disconnected);
        last = e;
        note(std::string("reconnect failed: ") + e.what());
      } catch (...) {
        state_.store(CameraState::disconnected);
        last = to_error(std::current_exception(), "reconnect " + name());
      }
    }
    throw with_transcript(*last);
  });
}

std::future<void> Camera::disconnect() {
  return worker_->submit([this] {
    if (state_.load() != CameraState::disconnected) do_disconnect();
    state_.store(CameraState::disconnected);
  });
}

std::future<void> Camera::configure(CameraSettings wanted) {
  // Refused at once rather than queued: settings that silently apply after the running series
  // would make the next series differ from what the caller believes it asked for.
  if (series_pending_.load()) {
    std::promise<void> refused;
    refused.set_exception(std::make_exception_ptr(
        Error(ErrorInfo{.cls = ErrorClass::conflict,
                        .message = name() + " is busy with a capture series; settings unchanged",
                        .hint = "configure between series, not during one",
                        .retryable = true})));
    return refused.get_future();
  }
  return worker_->submit([this, wanted = std::move(wanted)] {
    require_connected();
    validate(wanted, limits(), name());
    try {
      do_configure(wanted);
    } catch (...) {
      Error e = to_error(std::current_exception(), "configure " + name());
      note(std::string("configure failed: ") + e.what());
      after_failure(e);
      throw with_transcript(e);
    }
    std::lock_guard lock(mutex_);
    settings_.merge(wanted);
    configured_.merge(wanted);
  });
}

namespace {

// Runs a future-returning operation's outcome into a callback without blocking anyone: the
// future is already satisfied when the worker task that produced it finishes.
void forward(std::future<void> f, WorkerThread& worker, OperationDone done) {
  auto shared = std::make_shared<std::future<void>>(std::move(f));
  auto deliver = [shared, done = std::move(done)] {
    try {
      shared->get();
      done(std::nullopt);
    } catch (const Error& e) {
      done(e);
    } catch (...) {
      done(to_error(std::current_exception(), "camera operation"));
    }
  };
  if (shared->wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    deliver();  // refused at once
  } else {
    worker.post(std::move(deliver));  // queued behind the operation itself
  }
}

}  // namespace

void Camera::connect(OperationDone done) { forward(connect(), *worker_, std::move(done)); }

void Camera::configure(CameraSettings settings, OperationDone done) {
  forward(configure(std::move(settings)), *worker_, std::move(done));
}

std::future<CaptureReport> Camera::capture(std::size_t n, FrameSink sink, CaptureOptions options) {
  auto promise = std::make_shared<std::promise<CaptureReport>>();
  auto result = promise->get_future();
  capture(
      n, std::move(sink), [promise](CaptureReport r) { promise->set_value(std::move(r)); }, options);
  return result;
}

void Camera::capture(std::size_t n, FrameSink sink, CaptureDone done, CaptureOptions options) {
  bool idle = false;
  if (!series_pending_.compare_exchange_strong(idle, true)) {
    CaptureReport r;
    r.requested = n;
    r.error = Error(ErrorInfo{.cls = ErrorClass::conflict,
                              .message = name() + " is busy with another capture series",
                              .hint = "wait for the running series to finish, then capture again",
                              .retryable = true});
    done(std::move(r));  // on the caller's thread: nothing was queued
    return;
  }
  worker_->post([this, n, sink = std::move(sink), done = std::move(done), options] {
    CaptureReport r = run_series(n, sink, options.queue_depth);
    series_pending_.store(false);
    done(std::move(r));
  });
}

void Camera::after_failure(const Error& e) {
  switch (e.cls()) {
    case ErrorClass::no_comms:
      do_disconnect();
      state_.store(CameraState::disconnected);
      break;
    case ErrorClass::hardware_fail:
    case ErrorClass::internal:
    case ErrorClass::protocol_error:
    case ErrorClass::coms_fail:
      state_.store(CameraState::fault);
      break;
    default:  // timeout, busy, misread, bad data: the camera itself is still usable
      state_.store(CameraState::ready);
  }
}

void Camera::deliver(CapturedFrame&& frame, std::size_t index, const FrameSink& sink) {
  RawImage image;
  if (frame.pixels) {
    image = frame.pixels->view();
  } else if (!frame.file_bytes.empty()) {
    image = RawDecoder::for_this_thread().decode_buffer(frame.file_bytes, frame.file_name);
  } else {
    throw Error(ErrorClass::internal, name() + ": frame " + std::to_string(index) + " carries no data",
                "driver bug: a captured frame must hold a raw file or pixels");
  }
  image.frame_index = index;
  image.timestamp = frame.timestamp;
  sink(image);
}

CaptureReport Camera::run_series(std::size_t n, const FrameSink& sink, std::size_t depth) {
  CaptureReport report;
  report.requested = n;
  try {
    require_connected();
  } catch (const Error& e) {
    report.error = e;
    return report;
  }
  state_.store(CameraState::busy);
  note("series of " + std::to_string(n) + " frames");
  try {
    do_begin_series(n);
  } catch (...) {
    report.error = to_error(std::current_exception(), "start series on " + name());
    note(std::string("series start failed: ") + report.error->what());
    after_failure(*report.error);
    report.error = with_transcript(*report.error);
    return report;
  }

  if (!pipeline_ || depth != 2) pipeline_ = std::make_unique<FramePipeline<CapturedFrame>>(depth);
  std::vector<std::filesystem::path> saved;  // touched only by the consumer until run() returns
  const PipelineRun run = pipeline_->run(
      n,
      [this](std::size_t i) {
        CapturedFrame f = do_capture_frame(i);
        note("frame " + std::to_string(i) + " captured " + f.file_name);
        return f;
      },
      [&](CapturedFrame&& f, std::size_t i) {
        auto files = std::move(f.saved_files);
        deliver(std::move(f), i, sink);
        saved.insert(saved.end(), files.begin(), files.end());
      });
  do_end_series();
  if (depth != 2) pipeline_ = std::make_unique<FramePipeline<CapturedFrame>>(2);

  report.delivered = run.consumed;
  report.saved_files = std::move(saved);
  report.capture_time = run.produce_time;
  report.decode_time = run.consume_time;
  report.wall_time = run.wall_time;
  if (run.error) {
    report.error = to_error(run.error, run.error_in_consumer ? "decode/deliver on " + name() : "capture on " + name());
    note(std::string(run.error_in_consumer ? "delivery failed: " : "capture failed: ") + report.error->what());
    report.error = with_transcript(*report.error);
    if (run.error_in_consumer) {
      state_.store(CameraState::ready);
    } else {
      after_failure(*report.error);
    }
  } else {
    state_.store(CameraState::ready);
  }
  if (report.error) {
    log::warning("camera", name() + ": series stopped after " + std::to_string(report.delivered) + " of " +
                               std::to_string(n) + " frames: " + report.error->what());
  }
  return report;
}

}  // namespace colorlab::drivers::camera
