// Two executions at once on one lab. The daemon now refuses a second start while one is unfinished (LabBusy),
// but two can still run together: resume_unfinished relaunches every execution a database from before that
// refusal left running. A call suspends (the camera, the keeping worker) while the other execution's calls go on;
// the frames a call keeps must still be named in the steps of the execution whose call kept them. Truth: the
// keeper's own list of what it kept, all of it kept by A's calls. Bound, exact: every reference the keeper handed out is in A's steps, in the order
// kept, none in B's, and no execution's ledger is left once both have ended.
//
// The interleaving is forced, not hoped for: A's call keeps its average, then its preview, and the keeper holds the
// preview (on the keeping worker, A's call suspended) until B has made two more lab calls. With one ledger for the
// lab, B's call clears A's average from it (A's step names fewer blobs than were kept).
#include <gtest/gtest.h>

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/io_context.hpp>

#include "../drivers/camera/sim_fixture.hpp"
#include "colorlab/campaigns/engine.hpp"
#include "colorlab/drivers/camera/camera_instrument.hpp"
#include "colorlab/drivers/camera/simulated_camera.hpp"
#include "engine_harness.hpp"

namespace colorlab::campaigns {
namespace {

namespace asio = boost::asio;
namespace cam = drivers::camera;
using nlohmann::json;
using testing::MemorySink;
using testing::script_from;

// Counts B's lab calls as its steps commit (one commit before each live call) and lets the keeper wait for them.
class CallGate {
 public:
  void committed() {
    std::lock_guard lock(mutex_);
    ++commits_;
    changed_.notify_all();
  }
  void ended() {
    std::lock_guard lock(mutex_);
    ended_ = true;
    changed_.notify_all();
  }
  // Until the other execution has made `calls` more calls (or has ended: then there is nothing to wait for).
  void await_calls(int calls) {
    std::unique_lock lock(mutex_);
    const int until = commits_ + calls;
    changed_.wait(lock, [&] { return commits_ >= until || ended_; });
  }
  int commits() {
    std::lock_guard lock(mutex_);
    return commits_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  int commits_ = 0;
  bool ended_ = false;
};

// Stores nothing; hands out a fresh reference per keep and notes it. Holds each preview until B has made two calls.
class HoldingKeeper final : public FrameKeeper {
 public:
  explicit HoldingKeeper(CallGate& gate) : gate_(gate) {}
  KeptBlob keep_bytes(const std::string& name, const std::string& kind, const std::string& media_type, const json& meta,
                      std::span<const std::uint8_t> bytes) override {
    return handed(KeptBlob{"", name, kind, media_type, bytes.size(), meta});
  }
  KeptBlob keep_file(const std::string& name, const std::string& kind, const std::string& media_type, const json& meta,
                     const std::filesystem::path&) override {
    return handed(KeptBlob{"", name, kind, media_type, 1, meta});
  }
  KeptBlob keep_preview(const std::string& name, const KeptBlob& of) override {
    gate_.await_calls(2);
    return handed(KeptBlob{"", name, "preview", "image/png", 1, json{{"preview_of", of.sha256}}});
  }
  std::vector<KeptBlob> kept() {
    std::lock_guard lock(mutex_);
    return kept_;
  }

 private:
  KeptBlob handed(KeptBlob b) {
    std::lock_guard lock(mutex_);
    b.sha256 = "kept-" + std::to_string(kept_.size() + 1);
    kept_.push_back(b);
    return b;
  }
  CallGate& gate_;
  std::mutex mutex_;
  std::vector<KeptBlob> kept_;
};

const char* kKeeping = R"lua(
return {
  run = function(p)
    for k = 1, 2 do lab.camera.capture({ frames = 2, keep = { "average", "preview" } }) end
    return true
  end,
}
)lua";

// Lab calls that keep nothing, until it is aborted.
const char* kWaiting = R"lua(
return {
  run = function(p)
    while true do lab.wait(0.001) end
  end,
}
)lua";

ScriptRunSetup setup_of(const char* name, const char* source) {
  ScriptRunSetup s;
  s.script = script_from(name, source);
  s.params = s.script->validate(json::object());
  s.random_seed = 1;
  return s;
}

std::vector<KeptBlob> blobs_of(const MemorySink& sink) {
  std::vector<KeptBlob> out;
  for (const auto& c : sink.commits) out.insert(out.end(), c.blobs.begin(), c.blobs.end());
  return out;
}

TEST(KeepPerExecution, TwoExecutionsAtOnceEachStepNamesWhatItsOwnCallKept) {
  cam::test::TempDir dir;
  cam::SimulatedCameraOptions o;
  o.model = cam::test::small_model();
  o.capture_dir = dir.path();
  InstrumentSet instruments;
  instruments.add(std::make_shared<cam::CameraInstrument>("cam", dir.path().string(), true,
                                                          std::make_unique<cam::SimulatedCamera>(o)));

  asio::io_context io;
  LabOptions options;
  options.time_scale = 1000;
  Lab lab(io.get_executor(), instruments, options);
  CallGate gate;
  HoldingKeeper keeper(gate);
  lab.set_frame_keeper(&keeper);

  MemorySink sink_a, sink_b;
  sink_b.on_commit = [&](std::size_t) { gate.committed(); };
  ExecutionControl control_a, control_b;
  control_a.execution_id = "A";
  control_b.execution_id = "B";
  std::optional<RunOutcome> outcome_a, outcome_b;
  int b_calls_when_a_ended = 0;

  asio::co_spawn(
      io,
      [&]() -> asio::awaitable<void> {
        outcome_a = co_await run_campaign_script(setup_of("keeping", kKeeping), lab, sink_a, control_a);
        b_calls_when_a_ended = gate.commits();
        control_b.request = ExecutionControl::Request::abort;
        control_b.reason = "A has ended";
      },
      asio::detached);
  asio::co_spawn(
      io,
      [&]() -> asio::awaitable<void> {
        outcome_b = co_await run_campaign_script(setup_of("waiting", kWaiting), lab, sink_b, control_b);
        gate.ended();
      },
      asio::detached);
  io.run();

  ASSERT_TRUE(outcome_a && outcome_b);
  ASSERT_EQ(outcome_a->kind, RunOutcome::Kind::finished) << (outcome_a->error ? outcome_a->error->what() : "");
  ASSERT_EQ(outcome_b->kind, RunOutcome::Kind::aborted) << (outcome_b->error ? outcome_b->error->what() : "");
  // The hold was met by B's calls, not by B's end: the calls did interleave.
  ASSERT_GE(b_calls_when_a_ended, 4) << "B made too few calls while A kept its frames";

  const auto kept = keeper.kept();
  ASSERT_EQ(kept.size(), 4u) << "two calls, each an average and its preview";
  const auto in_a = blobs_of(sink_a);
  std::vector<std::string> kept_sha, a_sha, a_names;
  for (const auto& b : kept) kept_sha.push_back(b.sha256);
  for (const auto& b : in_a) {
    a_sha.push_back(b.sha256);
    a_names.push_back(b.name);
  }
  EXPECT_EQ(a_sha, kept_sha) << "every frame A's calls kept is named in A's steps, in the order kept";
  EXPECT_EQ(a_names, (std::vector<std::string>{"camera.capture#0/average", "camera.capture#0/average.png",
                                               "camera.capture#1/average", "camera.capture#1/average.png"}));
  EXPECT_TRUE(blobs_of(sink_b).empty()) << "B kept nothing, so its steps name nothing";
  EXPECT_EQ(lab.executions_keeping(), 0u) << "an execution's ledger goes when it ends";
}

}  // namespace
}  // namespace colorlab::campaigns
