// The composition root: builds colorlabd's services (daemon/core) and hands the HTTP server the API's router
// (daemon/api), which places each request on the pool or the main thread as its route's row says.
#include "daemon.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/use_awaitable.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/core/thread_account.hpp"
#include "colorlab/core/thread_priority.hpp"
#include "colorlab/campaigns/catalogue.hpp"
#include "colorlab/campaigns/lab.hpp"
#include "colorlab/api/access.hpp"
#include "colorlab/api/console_files.hpp"
#include "colorlab/api/context.hpp"
#include "colorlab/api/router.hpp"
#include "colorlab/daemon/blob_service.hpp"
#include "colorlab/daemon/embedded_sim.hpp"
#include "colorlab/daemon/event_hub.hpp"
#include "colorlab/daemon/read_connections.hpp"
#include "colorlab/daemon/report_service.hpp"
#include "colorlab/daemon/executions.hpp"
#include "colorlab/daemon/io_watch.hpp"
#include "colorlab/daemon/simulator_hands.hpp"
#include "colorlab/daemon/step_committer.hpp"
#include "colorlab/daemon/night_queue.hpp"
#include "colorlab/daemon/notifier.hpp"
#include "colorlab/daemon/store_run_reader.hpp"
#include "colorlab/daemon/systemd_notify.hpp"
#include "colorlab/daemon/worker_pool.hpp"
#include "colorlab/drivers/discovery_monitor.hpp"
#include "colorlab/http/server.hpp"
#include "colorlab/store/writer_wait.hpp"
#include "colorlab/verify/cabinet_json.hpp"

namespace colorlab::daemon {

namespace asio = boost::asio;

struct Daemon::Impl {
  DaemonConfig config;
  asio::io_context io{1};
  std::unique_ptr<EmbeddedSim> sim;
  std::unique_ptr<store::Store> store;
  std::unique_ptr<BlobService> blobs;  // the image store (blob_service.hpp)
  AccessControl access;                // the policy and the control lock (access.hpp)
  campaigns::InstrumentSet instruments;
  std::unique_ptr<campaigns::ScriptCatalogue> catalogue;
  std::unique_ptr<campaigns::Lab> lab;
  campaigns::OperatorDesk desk;
  std::unique_ptr<SimulatorHands> hands;
  std::unique_ptr<StoreRunReader> run_reader;  // lab.runs.* (characterize-camera's reference)
  std::unique_ptr<WorkerPool> workers;         // fits and dry runs' analyses (worker_pool.hpp); outlives executions
  std::unique_ptr<StepCommitter> committer;    // steps' commits off the io thread (step_committer.hpp); outlives executions
  std::unique_ptr<Notifier> notices;           // [notify]: tells the operator (notifier.hpp); outlives executions
  std::unique_ptr<Executions> executions;
  std::unique_ptr<NightQueue> queue;
  std::unique_ptr<ReadConnections> readers;
  std::unique_ptr<EventHub> events;
  std::unique_ptr<ReportService> reports;  // runs' reports, made by the Python client (report_service.hpp)
  std::unique_ptr<ApiContext> api;
  std::unique_ptr<http::Server> server;
  std::unique_ptr<drivers::Discovery> discovery;
  std::unique_ptr<drivers::DiscoveryMonitor> monitor;
  std::vector<std::shared_ptr<drivers::Instrument>> connect_at_start;
  SystemdNotifier notifier{io};
  IoLagMonitor lag{io.get_executor()};  // COLORLAB_IO_LAG_MS: how late the io thread answers (io_watch.hpp)

  void on_discovery_change(const drivers::DiscoveryChange& change);
};

namespace {

// Where one answer's time went, in ms, for its Server-Timing header (docs/API.md, "Which routes wait on what"):
// queue — from the request read until its handler started (for a `main` row, the wait for the main thread);
// handler — its run, of which cpu on a CPU and store on the store's writer; later — a heavy route's answer awaited.
struct AnswerTiming {
  std::chrono::steady_clock::time_point received = std::chrono::steady_clock::now();
  std::chrono::microseconds queue{0}, handler{0}, cpu{0}, store{0}, later{0};

  std::string header() const {
    return http::server_timing_metric("queue", queue) + ", " + http::server_timing_metric("handler", handler) + ", " +
           http::server_timing_metric("cpu", cpu) + ", " + http::server_timing_metric("store", store) + ", " +
           http::server_timing_metric("later", later);
  }
};

// Times one handler's run on the thread running it: one synchronous call, so the thread's counters across it (CPU
// time, the wait on the store's writer) are the handler's own.
class HandlerTiming {
 public:
  explicit HandlerTiming(AnswerTiming& timing)
      : timing_(timing),
        start_(std::chrono::steady_clock::now()),
        cpu_(this_thread_cpu_time()),
        store_us_(store::writer_wait_us_this_thread()) {
    timing_.queue = std::chrono::duration_cast<std::chrono::microseconds>(start_ - timing_.received);
  }
  ~HandlerTiming() {
    timing_.handler = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - start_);
    timing_.cpu = std::chrono::duration_cast<std::chrono::microseconds>(this_thread_cpu_time() - cpu_);
    timing_.store = std::chrono::microseconds(store::writer_wait_us_this_thread() - store_us_);
  }
  HandlerTiming(const HandlerTiming&) = delete;
  HandlerTiming& operator=(const HandlerTiming&) = delete;

 private:
  AnswerTiming& timing_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::nanoseconds cpu_;
  std::int64_t store_us_;
};

asio::awaitable<void> connect_instrument(std::shared_ptr<drivers::Instrument> instrument) {
  try {
    co_await instrument->connect();
    log::info("colorlabd", instrument->id() + " ready on " + instrument->identity().port);
  } catch (const Error& e) {
    log::warning("colorlabd", instrument->id() + ": " + e.what() + (e.hint().empty() ? "" : " — " + e.hint()));
  }
}

}  // namespace

// Instruments that come and go: recorded in the event log, configured ones (re)connected when
// their port appears and released when it disappears.
void Daemon::Impl::on_discovery_change(const drivers::DiscoveryChange& change) {
  const auto& d = change.instrument;
  log::info("colorlabd", std::string(change.added ? "instrument appeared: " : "instrument went away: ") + d.id + " (" +
                             d.kind + " on " + d.port + ")");
  try {
    store->append_event("instrument", {{"event", change.added ? "added" : "removed"},
                                       {"id", d.id},
                                       {"kind", d.kind},
                                       {"port", d.port},
                                       {"from_config", d.from_rule}});
  } catch (const Error& e) {
    log::warning("colorlabd", std::string("cannot record a discovery event: ") + e.what());
  }
  auto instrument = instruments.find(d.id);
  if (!instrument) return;
  if (!change.added) {
    instrument->disconnect();
  } else if (instrument->state() == drivers::InstrumentState::disconnected) {
    asio::co_spawn(io, connect_instrument(instrument), asio::detached);
  }
}

Daemon::Daemon(DaemonConfig config) : impl_(std::make_unique<Impl>()) {
  auto& d = *impl_;
  d.config = std::move(config);
  // Before any heavy thread starts (the blob check, cameras' decode threads): they lower themselves by it.
  core::set_heavy_thread_nice(d.config.priority.heavy_work_nice);
  d.config.simulator.nice = d.config.priority.simulator_nice;
  // The database first: if it is unusable, nothing else should start.
  d.store = std::make_unique<store::Store>(d.config.database_path());
  d.blobs = std::make_unique<BlobService>(d.io, *d.store, d.config.state_dir, d.config.blobs);
  d.blobs->start_check();  // files without rows, rows without files: reported, never deleted
  // Then access control: an insecure listener is refused before anything starts.
  d.access = make_access_control(d.config, *d.store, d.io);

  auto instrument_configs = d.config.instruments;
  if (d.config.simulator.enabled) {
    d.sim = std::make_unique<EmbeddedSim>(default_sim_binary(), d.config.simulator, d.config.state_dir / "sim");
    for (auto& c : d.sim->instruments()) instrument_configs.push_back(std::move(c));
  }
  for (const auto& c : instrument_configs) {
    try {
      d.instruments.add(drivers::make_instrument(d.io.get_executor(), c));
    } catch (const Error& e) {
      // One unusable entry must not keep the others (and the stored data) offline; it is listed as absent.
      log::warning("colorlabd", std::string("instrument skipped: ") + e.what());
      d.instruments.add_absent({c.id, c.kind, c.port, c.simulated,
                                std::string(e.what()) + (e.hint().empty() ? "" : " (" + e.hint() + ")")});
    }
  }
  if (d.sim) {
    for (auto& a : d.sim->absent_instruments()) d.instruments.add_absent(std::move(a));
  }
  std::vector<drivers::DiscoveryRule> rules;
  for (const auto& c : instrument_configs) {
    // Device paths are watched; network addresses (GenICam cameras) are simply connected at start.
    if (d.instruments.find(c.id) && c.port.starts_with('/')) {
      rules.push_back(drivers::DiscoveryRule{c.id, c.kind, c.port, {}, {}, {}});
    } else if (auto i = d.instruments.find(c.id)) {
      d.connect_at_start.push_back(i);
    }
  }
  d.discovery = std::make_unique<drivers::Discovery>(std::move(rules));

  std::error_code ec;
  std::filesystem::create_directories(d.config.campaign_dir(), ec);
  d.catalogue = std::make_unique<campaigns::ScriptCatalogue>(std::vector<campaigns::CampaignDirectory>{
      {campaigns::shipped_campaign_dir(), "shipped"}, {d.config.campaign_dir(), "lab"}});
  if (d.catalogue->all().empty()) {
    log::warning("colorlabd", "no campaign scripts found in " + campaigns::shipped_campaign_dir().string() + " or " +
                                  d.config.campaign_dir().string());
  }
  campaigns::LabOptions lab_options;
  const auto& cc = d.config.campaigns;
  lab_options.time_scale = cc.time_scale;
  if (d.sim) lab_options.time_scale = d.sim->announcement().value("time_scale", 1.0);
  lab_options.warmup = {cc.stable_tolerance_pct, cc.stable_window_s, cc.stable_interval_s, cc.stable_timeout_s};
  lab_options.lamp_warmup_s = cc.lamp_warmup_s;
  lab_options.lamps_off_at_shutdown = cc.lamps_off_at_shutdown;
  lab_options.suspend.retry_s = cc.suspend_retry_s;
  lab_options.suspend.settle_s = cc.suspend_settle_s;
  lab_options.suspend.max_s = cc.suspend_max_s;
  d.lab = std::make_unique<campaigns::Lab>(d.io.get_executor(), d.instruments, lab_options);
  if (d.sim && d.sim->announcement().contains("control")) {
    d.hands = std::make_unique<SimulatorHands>(d.io.get_executor(), d.sim->announcement()["control"].get<std::string>());
  }
  d.lab->set_operator(&d.desk, d.hands.get());
  d.run_reader = std::make_unique<StoreRunReader>(*d.store);
  d.lab->set_run_reader(d.run_reader.get());
  d.lab->set_frame_keeper(d.blobs.get());
  d.desk.set_listener([&d](const std::string& event, const campaigns::OperatorRequest& r) {
    log::info("operator", event + ": " + r.prompt + (r.answer ? " → " + *r.answer + " (" + r.answered_by + ")" : ""));
    try {
      d.store->append_event("operator", {{"event", event}, {"request", r.to_json()}});
    } catch (const Error& e) {
      log::warning("operator", std::string("cannot record the request: ") + e.what());
    }
  });
  // Fits, analyses and dry runs' analyses: off the io thread (worker_pool.hpp).
  d.workers = std::make_unique<WorkerPool>(d.io.get_executor(), with_test_hooks(WorkerPoolOptions{.nice = d.config.priority.heavy_work_nice}));
  // The latency probe's A/B switch (bench/service/latency_ab.sh): the same binary committing steps and
  // checkpointing the WAL on the io thread as before, for a before/after in one run. Never for a lab: durability is
  // the same, latency is not.
  const char* on_io = std::getenv("COLORLAB_BENCH_COMMIT_ON_IO_THREAD");
  const bool commit_on_io_thread = on_io && std::string(on_io) == "1";
  d.committer = std::make_unique<StepCommitter>(d.io.get_executor(), d.config.database_path(),
                                                commit_on_io_thread ? nullptr : d.store.get());
  ExecutionOptions execution_options;
  execution_options.workers = d.workers.get();
  if (!commit_on_io_thread) execution_options.committer = d.committer.get();
  execution_options.crash_loop = {cc.max_resume_attempts, cc.crash_loop_backoff_s, cc.crash_loop_backoff_max_s,
                                  cc.crash_loop_retries};
  execution_options.state_dir = d.config.state_dir;
  if (d.config.notify.enabled()) {
    d.notices = std::make_unique<Notifier>(d.config.notify);
    execution_options.notifier = d.notices.get();
  }
  d.executions = std::make_unique<Executions>(d.io, *d.store, *d.catalogue, d.instruments, *d.lab, execution_options,
                                              [&d](const std::string& text) { d.notifier.status(text); });
  d.queue = std::make_unique<NightQueue>(d.io, *d.store, *d.executions, *d.catalogue, *d.lab,
                                         QueueOptions{d.config.queue.autostart});
  d.readers = std::make_unique<ReadConnections>(d.config.database_path());
  d.events = std::make_unique<EventHub>(
      [readers = d.readers.get()] { return readers->for_this_thread().last_event_seq(); },
      std::chrono::milliseconds(20));
  d.events->start();
  d.api = std::make_unique<ApiContext>(ApiContext{*d.store, d.instruments, *d.catalogue, *d.executions,
                                                  d.config.simulator.enabled, now_iso8601(), d.discovery.get(), "",
                                                  &d.desk, d.queue.get()});
  d.api->readers = d.readers.get();
  d.api->events = d.events.get();
  d.api->access = d.access.access.get();
  d.api->control = d.access.lock.get();
  d.api->blobs = d.blobs.get();
  d.api->console_dir = shipped_console_dir();
  d.api->cabinet = {{"source", d.config.cabinet ? "config" : "default"},
                    {"cabinet", verify::cabinet_to_json(d.config.cabinet.value_or(verify::default_cabinet()))}};
  d.api->lenses = {{"items", nlohmann::json::array()}};
  for (const auto& l : d.config.lenses) d.api->lenses["items"].push_back(verify::lens_to_json(l));
  ReportService::Options report_options;
  report_options.directory = d.config.state_dir / "reports";
  report_options.unix_socket = d.config.socket_path();
#ifdef COLORLAB_VERSION
  report_options.version = COLORLAB_VERSION;
#endif
  report_options.nice = d.config.priority.heavy_work_nice;
  d.reports = std::make_unique<ReportService>(report_options);
  d.api->reports = d.reports.get();

  http::ServerOptions so;
  so.tcp_host = d.config.listen_host;
  so.tcp_port = d.config.listen_port;
  so.unix_socket = d.config.socket_path();
  so.tls_certificate = d.config.access.tls_certificate.value_or("");
  so.tls_private_key = d.config.access.tls_private_key.value_or("");
  so.threads = d.config.api.threads;
  so.max_connections = d.config.api.max_connections;
  so.stream_write_timeout = std::chrono::milliseconds(static_cast<long>(d.config.api.stream_write_timeout_s * 1000));
  // A diagnostic, opt-in like the lag monitor (a loaded machine would fill the log): with COLORLAB_IO_SLOW_MS set,
  // an answer slower than it is logged with where its time went, its writing included.
  if (std::getenv("COLORLAB_IO_SLOW_MS")) so.slow_answer_log = io_slow_threshold();
  // Stored data is served on the HTTP pool through read connections, so a commit's fsync never
  // stalls it; whatever touches live state (executions, instruments, the queue) runs on the main
  // thread. The route's row in the route table says which.
  auto handler = [api = d.api.get(), &io = d.io](http::HttpRequest& req) -> asio::awaitable<http::HttpResponse> {
    AnswerTiming timing;
    const Routed routed = route_request(req);
    http::HttpResponse answer;
    if (routed.placement() == Placement::pool) {
      HandlerTiming timed(timing);
      answer = handle_api(*api, req, routed);
    } else {
      // `req` and `routed` live in this coroutine's frame until the main thread has answered.
      answer = co_await asio::co_spawn(
          io,
          [api, &req, &routed, &timing]() -> asio::awaitable<http::HttpResponse> {
            NamedIoStage stage(routed.route ? "route " + std::string(routed.route->method) + " " +
                                                  std::string(routed.route->pattern)
                                            : std::string("route (none)"));
            HandlerTiming timed(timing);
            co_return handle_api(*api, req, routed);
          },
          asio::use_awaitable);
    }
    if (!answer.later) {
      answer.headers.try_emplace("Server-Timing", timing.header());
      co_return answer;
    }
    // A heavy route's answer (a dry run): awaited on the main thread, which serves meanwhile while
    // the work runs on the worker pool. `later` stays alive here until it has answered.
    const auto later = answer.later;
    const auto asked = std::chrono::steady_clock::now();
    auto answered = asio::co_spawn(io, later->answer(), asio::use_awaitable);
    http::HttpResponse late = co_await std::move(answered);
    timing.later = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - asked);
    late.headers.try_emplace("Server-Timing", timing.header());
    co_return late;
  };
  d.server = std::make_unique<http::Server>(d.io, so, http::AsyncHandler(handler));
  d.server->start();
}

Daemon::~Daemon() {
  std::error_code ec;
  std::filesystem::remove(endpoint_file_path(impl_->config), ec);
}

std::filesystem::path endpoint_file_path(const DaemonConfig& config) { return config.state_dir / "colorlabd.endpoint"; }

// Where this daemon listens, for clients and tests that asked for port 0. Written atomically.
void Daemon::write_endpoint_file() {
  auto& d = *impl_;
  nlohmann::json j{{"pid", ::getpid()},
                   {"url", std::string(d.config.access.tls_certificate ? "https://" : "http://") + d.config.listen_host + ":" + std::to_string(d.server->bound_port())},
                   {"port", d.server->bound_port()},
                   {"unix_socket", d.config.socket_path().string()}};
  if (d.sim) {
    j["simulator_pid"] = d.sim->pid();
    // Tests and demos inject faults and read the ground truth there.
    if (d.sim->announcement().contains("control")) j["simulator_control"] = d.sim->announcement()["control"];
  }
  auto path = endpoint_file_path(d.config);
  auto tmp = path;
  tmp += ".tmp";
  {
    std::ofstream out(tmp);
    out << j.dump() << "\n";
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
}

int Daemon::run() {
  auto& d = *impl_;
  // Connect instruments in the background: the API is useful (stored data) while they come up.
  // Discovery's first scan reports every present port as added, which starts each connection.
  d.discovery->subscribe([&d](const drivers::DiscoveryChange& c) { d.on_discovery_change(c); });
  for (const auto& instrument : d.connect_at_start) asio::co_spawn(d.io, connect_instrument(instrument), asio::detached);
  d.monitor = std::make_unique<drivers::DiscoveryMonitor>(d.io.get_executor(), *d.discovery);
  d.monitor->start();
  d.api->hotplug_status = d.monitor->hotplug_status();

  // Executions left by a previous process (crash, power cut, shutdown) continue by themselves.
  // After discovery's first scan, so instruments are already connecting when a resume needs them.
  d.executions->resume_unfinished();
  // Then the queue: it follows the item whose execution was just resumed instead of starting it again.
  d.queue->start_up();

  asio::signal_set signals(d.io, SIGINT, SIGTERM);
  signals.async_wait([&](boost::system::error_code ec, int sig) {
    if (ec) return;
    log::info("colorlabd", "signal " + std::to_string(sig) + ": stopping at the running steps' next safe point");
    d.notifier.stopping();
    d.lag.stop();
    d.server->stop();
    d.events->stop();  // event streams still waiting are woken (and end) while their io_contexts are alive
    d.monitor->stop();
    d.queue->shutdown();  // starts nothing more; stays started in the store for the next daemon
    // Running steps finish (or their waits are cut short), then the instruments go to a safe state.
    d.executions->shutdown([&d] {
      asio::co_spawn(
          d.io,
          [&d]() -> asio::awaitable<void> {
            co_await d.lab->safe_state();
            d.io.stop();
          },
          asio::detached);
    });
    // A second signal, or an instrument that never answers, must not keep the daemon alive.
    auto hard_stop = std::make_shared<asio::steady_timer>(d.io, std::chrono::seconds(20));
    hard_stop->async_wait([&d, hard_stop](boost::system::error_code) { d.io.stop(); });
    signals.async_wait([&d](boost::system::error_code e, int) {
      if (!e) d.io.stop();
    });
  });

  std::string where = d.config.listen_host + ":" + std::to_string(d.server->bound_port()) + " and " +
                      d.config.socket_path().string();
  write_endpoint_file();
  d.notifier.ready("serving on " + where);
  d.notifier.start_watchdog();
  d.lag.start();
  log::info("colorlabd", "serving the v1 API on " + where + (d.sim ? " (simulated lab)" : ""));
  d.io.run();
  return 0;
}

}  // namespace colorlab::daemon
