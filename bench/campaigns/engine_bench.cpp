// What the script layer costs, side by side in one run (interleave with
// --benchmark_enable_random_interleaving=true):
// - a campaign step through the Lua engine (the shipped luminance-spot.lua: lab.meter.measure,
//   lab.record, lab.progress, journal) against the same procedure written straight in C++ (the
//   driver call and the same StepCommit), both on the simulated LS-110 over a pty at time scale 1,
//   so a step costs what it costs on the bench (≈ 0.45 s);
// - the same two with a lab call that does no I/O (lab.now), which isolates the engine's own
//   per-call cost in microseconds.
// The issue's target: the script layer ≤ 1 % of a campaign's wall time, per step.
#include <benchmark/benchmark.h>

#include <fstream>
#include <sstream>
#include <thread>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/use_future.hpp>

#include "colorlab/campaigns/engine.hpp"
#include "colorlab/drivers/ls110.hpp"
#include "colorlab/sim/ls110_sim.hpp"

namespace {

namespace asio = boost::asio;
using namespace colorlab;
using nlohmann::json;

struct CountingSink final : campaigns::ExecutionSink {
  std::size_t commits = 0, rows = 0;
  void commit(const campaigns::StepCommit& s) override {
    ++commits;
    rows += s.measurements.size();
  }
  void restored(const json&) override {}
  void status_text(const std::string&) override {}
};

struct Bench {
  asio::io_context sim_io;
  std::unique_ptr<asio::executor_work_guard<asio::io_context::executor_type>> work;
  std::shared_ptr<sim::Ls110Sim> meter_sim;
  std::thread sim_thread;
  asio::io_context io;
  campaigns::InstrumentSet instruments;
  std::shared_ptr<drivers::Ls110> meter;
  std::unique_ptr<campaigns::Lab> lab;
  std::shared_ptr<campaigns::CampaignScript> spot, clock;

  Bench() {
    meter_sim = std::make_shared<sim::Ls110Sim>(
        sim_io.get_executor(), [] { return sim::Ls110Truth{300.0, 0.3}; }, 1, 1.0);
    meter_sim->start();
    work = std::make_unique<asio::executor_work_guard<asio::io_context::executor_type>>(sim_io.get_executor());
    sim_thread = std::thread([this] { sim_io.run(); });
    drivers::Ls110Options o;
    o.port = meter_sim->port_path();
    o.simulated = true;
    meter = std::make_shared<drivers::Ls110>(io.get_executor(), o);
    instruments.add(meter);
    lab = std::make_unique<campaigns::Lab>(io.get_executor(), instruments, campaigns::LabOptions{});
    std::ifstream in(std::string(COLORLAB_SOURCE_DIR) + "/campaigns/scripts/luminance-spot.lua");
    std::stringstream text;
    text << in.rdbuf();
    spot = std::make_shared<campaigns::CampaignScript>(campaigns::parse_campaign_script("luminance-spot", text.str()));
    clock = std::make_shared<campaigns::CampaignScript>(campaigns::parse_campaign_script("clock", R"lua(return {
      parameters = { n = { type = "integer", default = 1000 } },
      run = function(p)
        for i = 1, p.n do
          local t = lab.now()
          lab.record("t/" .. i, { quantity = "time", value = t.unix, unit = "s" })
        end
      end })lua"));
  }
  ~Bench() {
    work.reset();
    sim_io.stop();
    sim_thread.join();
  }
  template <class F>
  void run(F f) {
    auto future = asio::co_spawn(io, f(), asio::use_future);
    io.restart();
    io.run();
    future.get();
  }
};

Bench& bench() {
  static Bench b;
  return b;
}

constexpr int kReadings = 4;
constexpr int kCalls = 1000;

void BM_Ls110Step_Script(benchmark::State& state) {
  auto& b = bench();
  for (auto _ : state) {
    b.run([&]() -> asio::awaitable<void> {
      campaigns::ScriptRunSetup setup;
      setup.script = b.spot;
      setup.params = b.spot->validate({{"readings", kReadings}});
      CountingSink sink;
      campaigns::ExecutionControl control;
      auto o = co_await campaigns::run_campaign_script(setup, *b.lab, sink, control);
      if (o.kind != campaigns::RunOutcome::Kind::finished) throw std::runtime_error("script failed");
    });
  }
  state.SetItemsProcessed(state.iterations() * kReadings);
}

// The same procedure with no script: measure, then commit the reading with its journal entry and
// progress before the next measurement, exactly what the engine commits.
void BM_Ls110Step_Direct(benchmark::State& state) {
  auto& b = bench();
  for (auto _ : state) {
    b.run([&]() -> asio::awaitable<void> {
      CountingSink sink;
      campaigns::StepCommit pending;
      for (int i = 0; i < kReadings; ++i) {
        if (!pending.journal.empty()) {
          sink.commit(pending);
          pending = {};
        }
        auto r = co_await b.meter->measure_luminance();
        json result{{"luminance", r.luminance}, {"unit", r.unit}, {"instrument", b.meter->id()}, {"raw", r.raw_reply}};
        pending.journal.push_back({i, "meter.measure", json::array(), result});
        pending.measurements.push_back({
            "reading/" + std::to_string(i),
            b.meter->id(),
            true,
            "luminance",
            r.luminance,
            r.unit,
            {{"raw", r.raw_reply}},
        });
        pending.progress = static_cast<double>(i) / kReadings;
        pending.label = "reading/" + std::to_string(i);
      }
      sink.commit(pending);
    });
  }
  state.SetItemsProcessed(state.iterations() * kReadings);
}

void BM_LabCall_Script(benchmark::State& state) {
  auto& b = bench();
  for (auto _ : state) {
    b.run([&]() -> asio::awaitable<void> {
      campaigns::ScriptRunSetup setup;
      setup.script = b.clock;
      setup.params = b.clock->validate({{"n", kCalls}});
      CountingSink sink;
      campaigns::ExecutionControl control;
      auto o = co_await campaigns::run_campaign_script(setup, *b.lab, sink, control);
      if (o.kind != campaigns::RunOutcome::Kind::finished) throw std::runtime_error("script failed");
    });
  }
  state.SetItemsProcessed(state.iterations() * kCalls);
}

void BM_LabCall_Direct(benchmark::State& state) {
  auto& b = bench();
  const std::string call = "now";
  const json args = json::array();
  campaigns::ExecutionControl control;
  for (auto _ : state) {
    b.run([&]() -> asio::awaitable<void> {
      CountingSink sink;
      campaigns::StepCommit pending;
      for (int i = 0; i < kCalls; ++i) {
        if (!pending.journal.empty()) {
          sink.commit(pending);
          pending = {};
        }
        json t = co_await b.lab->perform(call, args, control);
        pending.journal.push_back({i, call, args, t});
        pending.measurements.push_back({"t/" + std::to_string(i), "", false, "time", t["unix"].get<double>(), "s", nullptr});
      }
      sink.commit(pending);
    });
  }
  state.SetItemsProcessed(state.iterations() * kCalls);
}

}  // namespace

BENCHMARK(BM_Ls110Step_Script)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_Ls110Step_Direct)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_LabCall_Script)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LabCall_Direct)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
