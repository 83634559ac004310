// colorlabd's services that own a thread, driven across threads as the daemon drives them (issue 24: the daemon's
// threaded tests under ThreadSanitizer, docs/TESTING.md). The step committer's second writer commits two executions'
// steps while the first writer appends events on the io thread; the event hub watches the log through its own read
// connection and wakes streams waiting on two pool threads, which read the events through theirs; the blob store's
// check runs on its thread while two threads keep frames and a third asks how it goes; the notifier takes
// notifications from several threads at once. What is checked holds on any machine: every step once and in order,
// every waiter sees every step, every kept frame whole, every notification delivered once. Every wait is bounded and
// says what it waited for.
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <set>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/thread_pool.hpp>
#include <boost/asio/use_future.hpp>
#include <gtest/gtest.h>

#include "colorlab/daemon/blob_service.hpp"
#include "colorlab/daemon/event_hub.hpp"
#include "colorlab/daemon/notifier.hpp"
#include "colorlab/daemon/read_connections.hpp"
#include "colorlab/daemon/step_committer.hpp"
#include "colorlab/store/blob_store.hpp"
#include "colorlab/store/store.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace colorlab::daemon {
namespace {

namespace asio = boost::asio;
using nlohmann::json;
using store::Store;
using testing::TempDir;
using namespace std::chrono_literals;

constexpr int kSteps = 12;  // per execution

store::ExecutionRecord new_execution(Store& writer, const std::string& name) {
  store::NewRun run;
  run.campaign = "luminance-spot";
  run.params = {{"readings", kSteps}, {"name", name}};
  run.simulated = true;
  run.instruments = json::array({{{"id", "ls110"}}});
  run.script_sha256 = "s-" + name;
  run.script_source = "x";
  return writer.create_execution(run).execution;
}

store::StepRecord step_of(int i) {
  store::StepRecord step;
  const std::string label = "reading/" + std::to_string(i);
  step.journal.push_back({i, "meter.measure", json::array(), {{"luminance", 100.0 + i}}});
  step.measurements.push_back({label, "ls110", true, "luminance", 100.0 + i, "cd/m2", nullptr});
  step.progress = static_cast<double>(i + 1) / kSteps;
  step.step = label;
  return step;
}

// The daemon's main thread: an io_context run on a thread of its own, stopped and joined however the test ends.
struct IoThread {
  asio::io_context io;
  asio::executor_work_guard<asio::io_context::executor_type> work = asio::make_work_guard(io);
  std::thread thread{[this] { io.run(); }};
  ~IoThread() {
    work.reset();
    io.stop();
    thread.join();
  }
};

// A live event stream as the API's runs it on the HTTP pool: waits on the hub, then reads what is new through its
// thread's own connection. Returns the steps of progress events seen, per execution, in the order read.
asio::awaitable<std::map<std::string, std::vector<std::string>>> follow(EventHub& hub, ReadConnections& readers,
                                                                        std::int64_t after, std::size_t expected) {
  std::map<std::string, std::vector<std::string>> seen;
  std::size_t count = 0;
  const auto deadline = std::chrono::steady_clock::now() + 120s;
  while (count < expected && std::chrono::steady_clock::now() < deadline) {
    co_await hub.wait_beyond(after, 1000ms);
    for (const auto& e : readers.for_this_thread().events(after, 1000, std::nullopt)) {
      after = e.seq;
      if (e.topic != "progress") continue;
      seen[e.payload.value("execution_id", "")].push_back(e.payload.value("step", ""));
      ++count;
    }
  }
  co_return seen;
}

TEST(ThreadServices, TwoWritersCommitWhileTheHubWakesStreamsOnPoolThreadsAndEachSeesEveryStepInOrder) {
  TempDir dir;
  const auto db = dir / "colorlab.db";
  Store writer(db);
  const auto a = new_execution(writer, "a");
  const auto b = new_execution(writer, "b");
  const std::int64_t start = writer.last_event_seq();

  IoThread main;  // the first writer's only user from here on
  auto& io = main.io;
  ReadConnections readers(db);
  EventHub hub([&readers] { return readers.for_this_thread().last_event_seq(); }, 5ms);
  hub.start();
  StepCommitter committer(io.get_executor(), db);
  asio::thread_pool pool(2);  // the HTTP pool; joined first, as its streams use the hub and the connections

  // Two streams, each on its own strand of the pool, as two connections would be.
  std::vector<std::future<std::map<std::string, std::vector<std::string>>>> streams;
  for (int i = 0; i < 2; ++i) {
    streams.push_back(
        asio::co_spawn(asio::make_strand(pool), follow(hub, readers, start, 2 * kSteps), asio::use_future));
  }
  // Both executions commit through the second writer while the first writer records other events on the io thread.
  auto commit_all = [&committer](store::ExecutionRecord e) -> asio::awaitable<void> {
    for (int i = 0; i < kSteps; ++i) {
      auto step = step_of(i);  // named: GCC 12 mishandles some temporaries inside a co_await expression
      co_await committer.commit(e, std::move(step));
    }
  };
  auto first_writer = [&writer]() -> asio::awaitable<void> {
    for (int i = 0; i < kSteps; ++i) {
      writer.append_event("execution", {{"note", i}});
      auto executor = co_await asio::this_coro::executor;
      co_await asio::post(executor, asio::use_awaitable);  // lets the commits' completions in between
    }
  };
  auto done_a = asio::co_spawn(io, commit_all(a), asio::use_future);
  auto done_b = asio::co_spawn(io, commit_all(b), asio::use_future);
  auto done_w = asio::co_spawn(io, first_writer(), asio::use_future);
  for (auto* f : {&done_a, &done_b, &done_w}) {
    ASSERT_EQ(f->wait_for(120s), std::future_status::ready) << "the commits did not end within 120 s";
    f->get();
  }

  std::vector<std::string> in_order;
  for (int i = 0; i < kSteps; ++i) in_order.push_back("reading/" + std::to_string(i));
  for (auto& s : streams) {
    ASSERT_EQ(s.wait_for(150s), std::future_status::ready) << "a stream did not see every step within its 120 s";
    auto seen = s.get();
    EXPECT_EQ(seen[a.id], in_order);
    EXPECT_EQ(seen[b.id], in_order);
  }
  // Read back on the io thread, the first writer's own.
  auto counts = asio::co_spawn(
      io, [&]() -> asio::awaitable<std::pair<std::size_t, std::int64_t>> {
        co_return std::make_pair(writer.measurements(a.run_id).size() + writer.measurements(b.run_id).size(),
                                 writer.last_event_seq());
      },
      asio::use_future);
  ASSERT_EQ(counts.wait_for(60s), std::future_status::ready);
  const auto [measurements, last] = counts.get();
  EXPECT_EQ(measurements, 2u * kSteps);
  EXPECT_EQ(last, start + 3 * kSteps);  // every step's progress event and the first writer's own
  // The hub caught up with the log (it polls every 5 ms; bounded, not timed).
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (hub.latest() < last && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(5ms);
  EXPECT_EQ(hub.latest(), last);

  pool.join();
  committer.shutdown();
  hub.stop();
}

// The io thread's connection hands the WAL's checkpoints to the committer (step_committer.hpp): through more commits
// on the io thread than the WAL holds before its threshold, that connection copies nothing itself and the committer's
// checkpoint does; once the committer has shut down, the io thread's connection checkpoints by itself again.
TEST(ThreadServices, TheIoThreadsConnectionLeavesTheWalsCheckpointsToTheCommitter) {
  TempDir dir;
  const auto db = dir / "colorlab.db";
  Store writer(db);
  const auto e = new_execution(writer, "a");
  const auto before = std::filesystem::file_size(db);
  IoThread main;  // the first writer's only user from here on
  StepCommitter committer(main.io.get_executor(), db, &writer);
  // 96 KiB a step: about 24 pages of the WAL, so 80 steps (7.5 MiB) cross the 1000-page threshold.
  auto big_step = [](int i) {
    auto step = step_of(i);
    step.measurements.front().data = {{"spectrum", std::string(96 * 1024, 'x')}};
    return step;
  };
  auto commit_on_io_thread = [&](int from, int to) {
    return asio::co_spawn(
        main.io,
        [&, from, to]() -> asio::awaitable<std::uint64_t> {
          for (int i = from; i < to; ++i) writer.commit_step(e, big_step(i));
          co_return writer.wal_checkpoints_run();
        },
        asio::use_future);
  };
  auto first = commit_on_io_thread(0, 80);
  ASSERT_EQ(first.wait_for(120s), std::future_status::ready) << "80 commits did not end within 120 s";
  EXPECT_EQ(first.get(), 0u) << "the io thread's connection checkpointed the WAL itself";
  auto deadline = std::chrono::steady_clock::now() + 60s;
  while (std::filesystem::file_size(db) < before + 3 * 1024 * 1024 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_GT(std::filesystem::file_size(db), before + 3 * 1024 * 1024)
      << "no checkpoint on the committer's thread copied the WAL within 60 s";

  committer.shutdown();
  auto second = commit_on_io_thread(80, 160);
  ASSERT_EQ(second.wait_for(120s), std::future_status::ready) << "80 more commits did not end within 120 s";
  EXPECT_GE(second.get(), 1u) << "without the committer, the io thread's connection no longer checkpoints";
}

TEST(ThreadServices, StoppingTheHubWakesAStreamThatWaitsOnAnotherThread) {
  TempDir dir;
  const auto db = dir / "colorlab.db";
  Store writer(db);
  ReadConnections readers(db);
  EventHub hub([&readers] { return readers.for_this_thread().last_event_seq(); }, 5ms);
  hub.start();
  asio::thread_pool pool(1);
  // Longer than the bound below: only the stop can end this wait in time.
  auto waited = asio::co_spawn(pool, hub.wait_beyond(writer.last_event_seq(), 300s), asio::use_future);
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (hub.waiting() == 0 && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(1ms);
  ASSERT_EQ(hub.waiting(), 1u) << "the stream did not start waiting within 60 s";
  hub.stop();
  ASSERT_EQ(waited.wait_for(60s), std::future_status::ready) << "stop() did not wake the waiting stream";
  EXPECT_FALSE(waited.get());
  EXPECT_TRUE(hub.stopped());
  pool.join();
}

TEST(ThreadServices, NotificationsFromSeveralThreadsAreEachDeliveredOnce) {
  TempDir dir;
  const auto file = dir / "notifications";
  NotifyConfig config;
  // One document per line: the notifier delivers one at a time, so lines never interleave.
  config.command = {"/bin/sh", "-c", "cat >> \"$1\"; echo >> \"$1\"", "notify", file.string()};
  config.timeout_s = 60;
  constexpr int kThreads = 4;
  constexpr int kEach = 4;
  Notifier notifier(config);
  std::vector<std::thread> senders;
  for (int t = 0; t < kThreads; ++t) {
    senders.emplace_back([&notifier, t] {
      for (int i = 0; i < kEach; ++i) notifier.notify("failed", {{"sender", t}, {"n", i}});
    });
  }
  for (auto& s : senders) s.join();
  std::vector<json> docs;
  const auto deadline = std::chrono::steady_clock::now() + 120s;
  while (std::chrono::steady_clock::now() < deadline) {
    docs.clear();
    std::ifstream in(file);
    std::string line;
    while (std::getline(in, line)) {
      if (!line.empty()) docs.push_back(json::parse(line, nullptr, false));
    }
    if (docs.size() >= kThreads * kEach) break;
    std::this_thread::sleep_for(10ms);
  }
  ASSERT_EQ(docs.size(), static_cast<std::size_t>(kThreads * kEach)) << "not every notification arrived within 120 s";
  std::set<std::pair<int, int>> seen;
  for (const auto& d : docs) {
    ASSERT_TRUE(d.is_object()) << "a notification is not one JSON document per line";
    EXPECT_EQ(d.value("event", ""), "failed");
    EXPECT_TRUE(d.contains("time") && d.contains("host"));
    seen.insert({d.value("sender", -1), d.value("n", -1)});
  }
  EXPECT_EQ(seen.size(), static_cast<std::size_t>(kThreads * kEach));
}

TEST(ThreadServices, TheBlobCheckRunsOnItsThreadWhileFramesAreKeptFromTwoOthers) {
  TempDir dir;
  IoThread main;
  Store writer(dir / "colorlab.db");
  BlobService blobs(main.io, writer, dir.path(), {});
  auto keep = [&blobs](const std::string& text) {
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(text.data());
    return blobs.keep_bytes("n", "raw", "application/octet-stream", json::object(),
                            std::span<const std::uint8_t>(bytes, text.size()));
  };
  // Eight frames a committed step owns, before the check starts.
  store::NewRun run;
  run.campaign = "frame-average";
  run.params = json::object();
  run.instruments = json::array();
  run.script_sha256 = "s";
  run.script_source = "x";
  const auto e = writer.create_execution(run).execution;
  store::StepRecord step;
  step.step = "s";
  for (int i = 0; i < 8; ++i) {
    const auto b = keep("committed frame " + std::to_string(i));
    step.blobs.push_back({b.sha256, "frame/" + std::to_string(i), b.kind, b.media_type, b.size, b.meta});
  }
  writer.commit_step(e, step);

  // The check starts on the io thread (it reads the rows through the writer there); two campaign threads keep frames
  // meanwhile, as the frame keeper's worker does during a night.
  auto started = asio::co_spawn(
      main.io, [&blobs]() -> asio::awaitable<void> {
        blobs.start_check();
        co_return;
      },
      asio::use_future);
  ASSERT_EQ(started.wait_for(60s), std::future_status::ready) << "the io thread did not start the check within 60 s";
  started.get();
  std::vector<std::future<std::vector<records::BlobRef>>> keepers;
  for (int t = 0; t < 2; ++t) {
    keepers.push_back(std::async(std::launch::async, [&keep, t] {
      std::vector<records::BlobRef> kept;
      for (int i = 0; i < 10; ++i) {
        kept.push_back(keep("frame " + std::to_string(i) + " of thread " + std::to_string(t)));
      }
      return kept;
    }));
  }
  json report;
  const auto deadline = std::chrono::steady_clock::now() + 120s;
  while (std::chrono::steady_clock::now() < deadline) {
    report = blobs.check_report();  // the API's question, from another thread than the check's and the io thread
    if (report.value("state", "") != "running") break;
    std::this_thread::sleep_for(5ms);
  }
  ASSERT_EQ(report.value("state", ""), "done") << report.dump();
  EXPECT_EQ(report.value("verified", ""), "sha256");
  EXPECT_EQ(report.value("rows", 0), 8);
  EXPECT_TRUE(report["missing"].empty()) << report.dump();
  EXPECT_TRUE(report["mismatched"].empty()) << report.dump();
  EXPECT_TRUE(report["partial"].empty()) << report.dump();
  for (auto& k : keepers) {
    ASSERT_EQ(k.wait_for(60s), std::future_status::ready) << "keeping frames did not end within 60 s";
    for (const auto& b : k.get()) {
      EXPECT_EQ(store::BlobStore::hash_file(blobs.files().path_of(b.sha256)), b.sha256) << "a kept frame is not whole";
    }
  }
  // The check's event was appended on the io thread, the writer's (before the report said done).
  auto events = asio::co_spawn(
      main.io, [&writer]() -> asio::awaitable<std::size_t> {
        co_return writer.events(0, 100, std::string("blobs")).size();
      },
      asio::use_future);
  ASSERT_EQ(events.wait_for(60s), std::future_status::ready);
  EXPECT_EQ(events.get(), 1u);
}

}  // namespace
}  // namespace colorlab::daemon
