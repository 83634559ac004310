#include "colorlab/daemon/executions.hpp"

#include <chrono>
#include <cmath>
#include <random>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/use_awaitable.hpp>

#include "colorlab/campaigns/dry_run.hpp"
#include "colorlab/campaigns/engine.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/daemon/blob_service.hpp"
#include "colorlab/daemon/campaign_request.hpp"
#include "colorlab/daemon/io_watch.hpp"
#include "colorlab/daemon/notifier.hpp"
#include "colorlab/daemon/step_committer.hpp"
#include "colorlab/daemon/worker_pool.hpp"
#include "colorlab/protocol/problem.hpp"

namespace colorlab::daemon {

namespace asio = boost::asio;
using nlohmann::json;
using protocol::ExecutionStatus;
using Request = campaigns::ExecutionControl::Request;

struct Executions::Active {
  store::ExecutionRecord record;
  campaigns::ExecutionControl control;
  // Why the execution is waiting out a condition right now; kept here too because a full disk
  // refuses to store it.
  std::optional<std::string> suspension;
};

namespace {

// The engine's persistence, over the store: one step, one transaction.
class StoreSink final : public campaigns::ExecutionSink {
 public:
  // `on_suspended` hears of each suspension (reason, problem, suspension document) to tell the operator.
  using SuspendedListener = std::function<void(const std::string&, const json&, const json&)>;
  StoreSink(store::Store& store, const store::ExecutionRecord& record, const campaigns::InstrumentSet& instruments,
            std::function<void(const std::string&)> status, json snapshot, bool replace_serials,
            std::optional<std::string>& suspension, double time_scale, SuspendedListener on_suspended,
            StepCommitter* committer)
      : committer_(committer),
        suspension_(suspension),
        on_suspended_(std::move(on_suspended)),
        time_scale_(time_scale),
        store_(store),
        record_(record),
        instruments_(instruments),
        status_(std::move(status)),
        snapshot_(std::move(snapshot)),
        replace_serials_(replace_serials) {}

  // The step's records go to the store as the engine made them (colorlab/core/step_records.hpp); the
  // sink adds only what the store keeps per run: serials learned since, and the lab's time scale.
  void commit(const campaigns::StepCommit& step) override {
    IoStage stage("commit step");
    store_.commit_step(record_, records_of(step));
  }
  // Every step the engine commits (before each live call, and the last when the run ends): on the committer's
  // thread, the io thread serving meanwhile (step_committer.hpp).
  asio::awaitable<void> commit_awaiting(const campaigns::StepCommit& step) override {
    if (!committer_) {
      commit(step);
      co_return;
    }
    co_await committer_->commit(record_, records_of(step));
  }
  void restored(const json& actions) override {
    store_.append_event("execution", {{"execution_id", record_.id}, {"run_id", record_.run_id}, {"restored", actions}});
    log::info("executions", record_.id + ": lab restored: " + actions.dump());
  }
  void status_text(const std::string& text) override {
    if (status_) status_(record_.campaign + " " + record_.id.substr(0, 8) + ": " + text);
  }
  void suspended(const std::string& reason, const Error& cause) override {
    suspension_ = reason;
    status_text("suspended: " + reason);
    const json problem = protocol::problem_from_error(cause).to_json();
    // The reason starts with the engine's cause: instrument, lamp or storage.
    const json document{{"category", reason.substr(0, reason.find(':'))}, {"problem", problem}};
    try {
      store_.set_execution_status(record_, ExecutionStatus::suspended, reason, json{{"suspended", true}, {"problem", problem}},
                                  document);
    } catch (const Error& e) {
      // A full disk refuses this too; the API still reports the suspension from memory.
      log::warning("executions", record_.id + ": cannot store the suspension: " + e.what());
    }
    if (on_suspended_) on_suspended_(reason, problem, document);
  }
  void resumed(const json& how) override {
    suspension_.reset();
    status_text("condition cleared, going on");
    try {
      store_.set_execution_status(record_, ExecutionStatus::running, "", json{{"resumed_after_suspension", how}});
    } catch (const Error& e) {
      log::warning("executions", record_.id + ": cannot store the end of the suspension: " + e.what());
    }
  }

 private:
  // The run's snapshot is taken when it is created, possibly before every instrument has connected
  // and named its serial. Serials learned since are written with the next step, so a resume can
  // tell whether the same unit is still there. A recorded serial is replaced only once an operator
  // has accepted another unit.
  store::StepRecord records_of(const campaigns::StepCommit& step) {
    return store::StepRecord{step.journal, step.measurements, step.progress, step.label,
                             updated_snapshot(), step.timings, time_scale_, step.blobs};
  }

  std::optional<json> updated_snapshot() {
    if (!snapshot_.is_array()) return std::nullopt;
    bool changed = false;
    for (auto& entry : snapshot_) {
      auto i = instruments_.find(entry.value("id", std::string()));
      if (!i) continue;
      auto serial = i->identity().serial;
      auto recorded = entry.value("serial", std::string());
      if (!serial.empty() && serial != recorded && (recorded.empty() || replace_serials_)) {
        entry = drivers::describe(*i);
        changed = true;
      }
    }
    replace_serials_ = false;
    if (!changed) return std::nullopt;
    return snapshot_;
  }

  StepCommitter* committer_ = nullptr;
  std::optional<std::string>& suspension_;
  SuspendedListener on_suspended_;
  double time_scale_ = 1;
  store::Store& store_;
  const store::ExecutionRecord& record_;
  const campaigns::InstrumentSet& instruments_;
  std::function<void(const std::string&)> status_;
  json snapshot_;
  bool replace_serials_ = false;
};

json problem_json(const Error& e, const json& location) {
  json problem = protocol::problem_from_error(e).to_json();
  if (!e.info().device_code.empty()) problem["device_code"] = e.info().device_code;
  if (!e.info().transcript.empty()) problem["transcript"] = e.info().transcript;
  if (location.is_object()) {
    for (const char* key : {"script", "line", "step", "traceback"}) {
      if (location.contains(key)) problem[key] = location[key];
    }
  }
  return problem;
}

std::uint64_t new_seed() {
  std::random_device rd;
  return (static_cast<std::uint64_t>(rd()) << 32 | rd()) & 0x7fffffffffffffffULL;
}

}  // namespace

Executions::Executions(asio::io_context& io, store::Store& store, campaigns::ScriptCatalogue& catalogue,
                       const campaigns::InstrumentSet& instruments, campaigns::Lab& lab, ExecutionOptions options,
                       std::function<void(const std::string&)> status_text)
    : io_(io),
      store_(store),
      catalogue_(catalogue),
      instruments_(instruments),
      lab_(lab),
      options_(options),
      status_text_(std::move(status_text)) {}

Executions::~Executions() = default;

asio::awaitable<json> Executions::dry_run(const std::string& campaign_name, const json& params) {
  auto [script, normalized] = validate_campaign_params(catalogue_, campaign_name, params);
  // A slot in the worker pool's queue for the whole dry run, refused (503) while the pool is full.
  std::shared_ptr<void> admitted = options_.workers ? options_.workers->admit("a dry run of " + campaign_name) : nullptr;
  campaigns::DryRunSetup setup;
  setup.script = script;
  setup.params = normalized;
  setup.instruments = &instruments_;
  setup.options = lab_.options();
  for (const auto& [key, t] : store_.call_timings(lab_.time_scale())) setup.timings[key] = {t.n, t.mean_s};
  setup.runs = lab_.run_reader();
  setup.hands = lab_.hands();
  setup.state_dir = options_.state_dir;
  // The script's lab calls are answered here, on the io thread, where the instruments live; its fits
  // run on the pool with their own copies of the data.
  if (auto* pool = options_.workers) {
    setup.compute = [pool](std::string what, std::function<json()> job) {
      return pool->run(std::move(what), std::move(job), Admission::always);
    };
  }
  auto report = campaigns::dry_run_campaign_async(std::move(setup));
  co_return co_await std::move(report);
}

LabBusy::LabBusy(const store::ExecutionRecord& holder)
    : Error(ErrorClass::conflict,
            "the lab is busy: execution " + holder.id + " (" + holder.campaign + ") is " +
                std::string(protocol::to_string(holder.status)),
            "wait for it to end or abort it (colorlab abort " + holder.id +
                "), or queue this campaign (colorlab queue add; colorlab queue start if the queue is stopped): the "
                "queue starts it when the lab is free, after the items before it"),
      execution_id_(holder.id) {}

store::ExecutionRecord Executions::start(const std::string& campaign_name, const json& params,
                                         const std::optional<std::string>& idempotency_key) {
  if (shutting_down_) throw Error(ErrorClass::conflict, "colorlabd is shutting down", "start the campaign after it restarts");
  auto [script, normalized] = validate_campaign_request(catalogue_, lab_, campaign_name, params);
  if (idempotency_key) {
    if (auto existing = store_.execution_with_idempotency_key(*idempotency_key)) return *existing;
  }
  if (auto unfinished = store_.unfinished_executions(); !unfinished.empty()) throw LabBusy(unfinished.front());

  store::NewRun run;
  run.campaign = campaign_name;
  run.params = normalized;
  run.idempotency_key = idempotency_key;
  run.instruments = json::array();
  for (const auto& i : instruments_.all()) {
    run.instruments.push_back(drivers::describe(*i));
    if (i->identity().simulated) run.simulated = true;
  }
  run.script_sha256 = script->sha256;
  run.script_source = script->source;
  run.random_seed = new_seed();
  auto created = store_.create_execution(run);
  if (!created.created) return created.execution;  // a retried POST with the same Idempotency-Key
  launch(created.execution, script, normalized, false);
  return created.execution;
}

void Executions::resume_unfinished() {
  for (const auto& record : store_.unfinished_executions()) {
    if (record.status == ExecutionStatus::paused) {
      log::info("executions", record.id + " stays paused (" + record.reason + "); resume it with `colorlab resume`");
      continue;
    }
    try {
      if (record.status == ExecutionStatus::suspended && is_crash_loop(record.suspension)) {
        // Stopped (or killed) during the guard's back-off: the back-off goes on where it was.
        const double backoff = record.suspension.value("backoff_s", options_.crash_loop.backoff_s);
        const double left = seconds_until(record.suspension.value("retry_at", std::string()), backoff,
                                          std::chrono::system_clock::now());
        log::info("executions", record.id + " stays suspended by the crash-loop guard; retrying in " +
                                    std::to_string(static_cast<long>(std::ceil(left))) + " s (or `colorlab resume`)");
        arm_backoff(record.id, left);
        continue;
      }
      // A clean shutdown suspended it; anything else means the process died during a step.
      if (record.status != ExecutionStatus::suspended) {
        int attempts = store_.begin_resume(record.id);
        if (judge_crash_loop(options_.crash_loop, attempts).kind != CrashLoopVerdict::Kind::resume) {
          crash_loop(record, attempts);
          continue;
        }
      }
      log::info("executions", "resuming " + record.id + " (" + record.campaign + ") from step '" + record.step + "'");
      relaunch(record, false);
    } catch (const Error& e) {
      log::error("executions", record.id + ": cannot resume: " + e.what());
      json problem = problem_json(e, nullptr);
      std::string why = std::string("cannot resume: ") + e.what();
      store_.finish_execution(record, ExecutionStatus::finished_error, record.step, nullptr, problem, why);
      notify("failed", record, why, problem);
    }
  }
}

// Not an instrument's failure: colorlabd itself kept dying in this step. Suspended with a back-off the
// daemon waits out by itself; once the retries are spent the run ends and its queue item's on_failure
// decides the rest of the night.
void Executions::crash_loop(const store::ExecutionRecord& record, int attempts) {
  const auto& policy = options_.crash_loop;
  const auto verdict = judge_crash_loop(policy, attempts);
  const std::string what = "colorlabd stopped " + std::to_string(attempts) + " times in a row during step '" + record.step +
                           "' without committing it";
  const std::string look = "look at the daemon's log (journalctl -u colorlabd) for what killed it";
  if (verdict.kind == CrashLoopVerdict::Kind::give_up) {
    // Laid out by hand: clang-format 14 joins a break inside a ?: operand into one 216-column line.
    // clang-format off
    std::string why = what + (policy.retries == 0 ? std::string(" (crash_loop_retries = 0)")
                                                  : ", also after " + std::to_string(policy.retries) + " retr" +
                                                        (policy.retries == 1 ? "y" : "ies") + " after a back-off") +
                      "; not resuming again";
    // clang-format on
    json problem = crash_loop_problem(why, look + "; start a new run when fixed");
    problem["step"] = record.step;
    json summary{{"measurements", store_.measurement_summary(record.run_id)}};
    store_.finish_execution(record, ExecutionStatus::finished_error, record.step, summary, problem, why);
    log::error("executions", record.id + ": " + why);
    notify("failed", record, why, problem);
    return;
  }
  const auto retry_at = std::chrono::system_clock::now() +
                        std::chrono::duration_cast<std::chrono::system_clock::duration>(
                            std::chrono::duration<double>(verdict.backoff_s));
  std::string why = "crash loop: " + what + "; colorlabd retries it by itself after " +
                    std::to_string(static_cast<long>(std::ceil(verdict.backoff_s))) + " s (retry " +
                    std::to_string(verdict.round) + " of " + std::to_string(policy.retries) + ")";
  json problem = crash_loop_problem(why, look + "; `colorlab resume` retries at once, `colorlab abort` gives the run up");
  problem["step"] = record.step;
  json suspension{{"category", kCrashLoopCategory},
                  {"problem", problem},
                  {"step", record.step},
                  {"restarts", attempts},
                  {"retry", verdict.round},
                  {"retries", policy.retries},
                  {"backoff_s", verdict.backoff_s},
                  {"retry_at", iso8601_utc(retry_at)}};
  store_.set_execution_status(record, ExecutionStatus::suspended, why, json{{"suspended", true}, {"problem", problem}},
                              suspension);
  log::error("executions", record.id + ": " + why);
  notify("crash-loop", record, why, problem, suspension);
  arm_backoff(record.id, verdict.backoff_s);
}

void Executions::arm_backoff(const std::string& id, double seconds) {
  cancel_backoff(id);
  auto timer = std::make_shared<asio::steady_timer>(io_);
  timer->expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds)));
  backoffs_[id] = timer;
  timer->async_wait([this, id, timer](boost::system::error_code ec) {
    if (ec) return;  // cancelled: resumed, aborted or shutting down
    if (auto it = backoffs_.find(id); it != backoffs_.end() && it->second == timer) backoffs_.erase(it);
    if (shutting_down_ || active_.count(id)) return;
    auto record = store_.execution(id);
    // Only what the guard itself suspended: an operator may have resumed or aborted it meanwhile.
    if (!record || record->status != ExecutionStatus::suspended || !is_crash_loop(record->suspension)) return;
    const int retry = record->suspension.value("retry", 0);
    log::info("executions", id + ": the crash-loop back-off is over; retrying step '" + record->step + "'");
    try {
      relaunch(*record, false, json{{"by", "back-off"}, {"retry", retry}});
    } catch (const Error& e) {
      log::error("executions", id + ": cannot resume: " + e.what());
      json problem = problem_json(e, nullptr);
      std::string why = std::string("cannot resume: ") + e.what();
      store_.finish_execution(*record, ExecutionStatus::finished_error, record->step, nullptr, problem, why);
      notify("failed", *record, why, problem);
    }
  });
}

void Executions::cancel_backoff(const std::string& id) {
  if (auto it = backoffs_.find(id); it != backoffs_.end()) {
    it->second->cancel();
    backoffs_.erase(it);
  }
}

void Executions::notify(const std::string& event, const store::ExecutionRecord& record, const std::string& reason,
                        const json& problem, const json& suspension) {
  if (!options_.notifier) return;
  json details{
      {"execution_id", record.id},
      {"run_id", record.run_id},
      {"campaign", record.campaign},
      {"step", record.step},
      {"reason", reason},
      {"problem", problem},
  };
  if (event == "failed") details["status"] = protocol::to_string(ExecutionStatus::finished_error);
  else details["status"] = protocol::to_string(ExecutionStatus::suspended);
  if (problem.is_object() && problem.contains("code")) details["category"] = problem["code"];
  if (suspension.is_object()) {
    details["suspension"] = suspension;
    details["category"] = suspension.value("category", std::string());
  }
  options_.notifier->notify(event, details);
}

// A run continues with the exact text and parameters it started with, never an edited file.
void Executions::relaunch(const store::ExecutionRecord& record, bool accept_units, json resumed_by) {
  auto source = store_.script_source(record.script_sha256);
  if (!source) throw Error(ErrorClass::not_found, "the run's script " + record.script_sha256 + " is missing from the store");
  auto script = std::make_shared<campaigns::CampaignScript>(campaigns::parse_campaign_script(record.campaign, *source));
  script->origin = "stored";
  auto run = store_.run(record.run_id);
  launch(record, script, run ? run->params : json::object(), true, accept_units, std::move(resumed_by));
}

void Executions::launch(store::ExecutionRecord record, std::shared_ptr<const campaigns::CampaignScript> script,
                        json params, bool resumed, bool accept_units, json resumed_by) {
  auto active = std::make_shared<Active>();
  active->record = record;
  active->control.execution_id = record.id;
  active_[record.id] = active;
  asio::co_spawn(
      io_,
      [this, active, script, params, resumed, accept_units, resumed_by]() -> asio::awaitable<void> {
        auto& record = active->record;
        campaigns::RunOutcome outcome;
        try {
          std::optional<IoStage> starting(std::in_place, "execution start");
          json how = resumed ? json{{"resumed", true}} : json(nullptr);
          if (resumed && resumed_by.is_object()) how["resumed_by"] = resumed_by;
          store_.set_execution_status(record, ExecutionStatus::running, resumed ? "resumed from step '" + record.step + "'" : "",
                                      how);
          campaigns::ScriptRunSetup setup;
          setup.script = script;
          setup.params = params;
          setup.random_seed = record.random_seed;
          setup.initial_label = record.step;
          setup.initial_progress = record.progress;
          if (auto* pool = options_.workers) {
            setup.compute = [pool](std::string what, std::function<json()> job) {
              return pool->run(std::move(what), std::move(job), Admission::always);
            };
          }
          auto run = store_.run(record.run_id);
          json snapshot = run ? run->instruments : json(nullptr);
          if (resumed) {
            for (auto& j : store_.journal(record.id)) setup.journal.push_back({j.seq, j.call, j.args, j.result});
            setup.stored_steps = store_.measurement_steps(record.run_id);
            for (const auto& i : snapshot.is_array() ? snapshot : json::array()) {
              if (i.contains("id") && i.contains("serial") && i["serial"].is_string()) {
                setup.expected_serials[i["id"].get<std::string>()] = i["serial"].get<std::string>();
              }
            }
            // An operator resuming a paused run has looked at the lab: accept the units as they are.
            setup.verify_serials = !accept_units;
          }
          StoreSink sink(
              store_, record, instruments_, status_text_, snapshot, resumed && accept_units, active->suspension,
              lab_.time_scale(), [this, &record](const std::string& reason, const json& problem, const json& doc) {
                notify("suspended", record, reason, problem, doc);
              },
              options_.committer);
          starting.reset();
          outcome = co_await campaigns::run_campaign_script(std::move(setup), lab_, sink, active->control);
        } catch (const Error& e) {
          outcome.kind = campaigns::RunOutcome::Kind::failed;
          outcome.error = e;
          if (e.cls() == ErrorClass::io_error) {
            outcome.kind = campaigns::RunOutcome::Kind::suspended;
            outcome.reason = std::string("storage: ") + e.what();
          }
        } catch (const std::exception& e) {
          outcome.kind = campaigns::RunOutcome::Kind::failed;
          outcome.error = Error(ErrorClass::internal, e.what());
        }
        try {
          IoStage ending("execution end");
          auto current = store_.execution(record.id);
          std::string step = current ? current->step : record.step;
          using Kind = campaigns::RunOutcome::Kind;
          switch (outcome.kind) {
            case Kind::finished: {
              json summary = store_.measurement_summary(record.run_id);
              summary = json{{"measurements", summary}, {"script", outcome.result}};
              store_.finish_execution(record, ExecutionStatus::finished_ok, "done", summary, nullptr, "");
              log::info("executions", record.id + " finished (" + std::to_string(outcome.calls) + " lab calls, " +
                                          std::to_string(outcome.replayed) + " replayed)");
              break;
            }
            case Kind::failed: {
              json summary{{"measurements", store_.measurement_summary(record.run_id)}};
              Error e = outcome.error ? *outcome.error : Error(ErrorClass::internal, "unknown failure");
              json problem = problem_json(e, outcome.script_location);
              store_.finish_execution(record, ExecutionStatus::finished_error, step, summary, problem, e.what());
              log::warning("executions", record.id + " failed: " + e.what());
              record.step = step;
              notify("failed", record, e.what(), problem);
              break;
            }
            case Kind::aborted: {
              json summary{{"measurements", store_.measurement_summary(record.run_id)}};
              store_.finish_execution(record, ExecutionStatus::aborted, step, summary, nullptr, outcome.reason);
              break;
            }
            case Kind::paused:
              store_.set_execution_status(record, ExecutionStatus::paused, outcome.reason);
              break;
            case Kind::suspended: {
              // A shutdown's suspension ends with the next start; the disk's is the operator's business, whether
              // the disk refused the run's start here or, in the engine, its last step's commit (both carry the
              // io_error; a shutdown's carries none).
              const bool storage_suspended = outcome.error && outcome.error->cls() == ErrorClass::io_error;
              json problem = storage_suspended ? protocol::problem_from_error(*outcome.error).to_json() : json(nullptr);
              json document{{"category", storage_suspended ? "storage" : "shutdown"}};
              if (!problem.is_null()) document["problem"] = problem;
              store_.set_execution_status(record, ExecutionStatus::suspended, outcome.reason, nullptr, document);
              if (storage_suspended) notify("suspended", record, outcome.reason, problem, document);
              break;
            }
          }
        } catch (const Error& e) {
          // The disk failed at the very end: what was committed stays committed; a restart resumes it.
          log::error("executions", record.id + ": cannot record the outcome: " + e.what());
        }
        active_.erase(record.id);
        maybe_done();
      },
      asio::detached);
}

std::optional<std::string> Executions::live_suspension(const std::string& id) const {
  auto it = active_.find(id);
  if (it == active_.end()) return std::nullopt;
  return it->second->suspension;
}

store::ExecutionRecord Executions::require(const std::string& id) {
  auto e = store_.execution(id);
  if (!e) throw Error(ErrorClass::not_found, "no execution with id '" + id + "'");
  return *e;
}

store::ExecutionRecord Executions::pause(const std::string& id) {
  auto record = require(id);
  auto it = active_.find(id);
  if (it == active_.end()) {
    if (record.status == ExecutionStatus::paused) return record;
    throw Error(ErrorClass::conflict,
                "execution " + id + " is " + std::string(protocol::to_string(record.status)) +
                    ", not running",
                "only a running execution can be paused");
  }
  it->second->control.request = Request::pause;
  it->second->control.reason = "paused by a client";
  store_.append_event("execution", {{"execution_id", id}, {"requested", "pause"}});
  return record;
}

store::ExecutionRecord Executions::resume(const std::string& id) {
  auto record = require(id);
  auto it = active_.find(id);
  if (it != active_.end()) {
    // Still running towards its safe point: simply cancel the pause.
    if (it->second->control.request == Request::pause) {
      it->second->control.request = Request::none;
      it->second->control.reason.clear();
    }
    return record;
  }
  if (record.status != ExecutionStatus::paused && record.status != ExecutionStatus::suspended) {
    throw Error(ErrorClass::conflict,
                "execution " + id + " is " + std::string(protocol::to_string(record.status)) +
                    ", not paused",
                "only a paused or suspended execution can be resumed");
  }
  if (shutting_down_) throw Error(ErrorClass::conflict, "colorlabd is shutting down");
  // One execution at a time holds the lab, a resumed one too (two are unfinished only in a database from before
  // that rule, or a restored backup).
  if (!active_.empty()) {
    if (auto other = store_.execution(active_.begin()->first)) throw LabBusy(*other);
  }
  const bool crash_loop = is_crash_loop(record.suspension);
  cancel_backoff(id);
  relaunch(record, record.status == ExecutionStatus::paused,
           crash_loop ? json{{"by", "a client"}, {"retry", record.suspension.value("retry", 0)}} : json(nullptr));
  return require(id);
}

store::ExecutionRecord Executions::abort(const std::string& id) {
  auto record = require(id);
  auto it = active_.find(id);
  if (it != active_.end()) {
    it->second->control.request = Request::abort;
    it->second->control.reason = "aborted by a client";
    store_.append_event("execution", {{"execution_id", id}, {"requested", "abort"}});
    return record;
  }
  if (protocol::is_terminal(record.status)) {
    throw Error(ErrorClass::conflict, "execution " + id + " has already ended (" +
                                          std::string(protocol::to_string(record.status)) + ")");
  }
  cancel_backoff(id);
  json summary{{"measurements", store_.measurement_summary(record.run_id)}};
  store_.finish_execution(record, ExecutionStatus::aborted, record.step, summary, nullptr, "aborted by a client");
  return require(id);
}

void Executions::shutdown(std::function<void()> done) {
  shutting_down_ = true;
  on_all_stopped_ = std::move(done);
  // A back-off under way stays in the store (retry_at): the next daemon waits out what is left of it.
  for (auto& [id, timer] : backoffs_) timer->cancel();
  backoffs_.clear();
  for (auto& [id, active] : active_) {
    if (active->control.request != Request::abort) {
      active->control.request = Request::shutdown;
      active->control.reason = "colorlabd stopped; it resumes when colorlabd starts again";
    }
  }
  maybe_done();
}

void Executions::maybe_done() {
  if (shutting_down_ && active_.empty() && on_all_stopped_) {
    auto done = std::move(on_all_stopped_);
    on_all_stopped_ = nullptr;
    done();
  }
}

}  // namespace colorlab::daemon
