#include "colorlab/campaigns/engine.hpp"

#include <chrono>
#include <exception>
#include <functional>
#include <memory>
#include <regex>
#include <utility>

#include <boost/asio/post.hpp>
#include <boost/asio/this_coro.hpp>
#include <boost/asio/use_awaitable.hpp>
#include <lua5.4/lua.hpp>

#include "colorlab/campaigns/lab_api.hpp"
#include "colorlab/campaigns/lab_state.hpp"
#include "colorlab/campaigns/lua_sandbox.hpp"
#include "colorlab/campaigns/lua_value.hpp"
#include "colorlab/core/log.hpp"
#include "run_thread.hpp"

namespace colorlab::campaigns {

namespace asio = boost::asio;
using nlohmann::json;

namespace {

// A lab call the script yielded with, as the engine carries it out.
struct PendingCall {
  std::string call;
  json args;
  CallKind kind = CallKind::control;
};

// One run of a campaign script: the script's coroutine, the journal it is replayed from, and the
// step gathered since the last commit. run() reads top to bottom: resume the script until it
// finishes, fails or stops; each lab call it yields with is answered from the journal while the
// replay lasts, then live.
class ScriptRun final : public LabCallSink {
 public:
  ScriptRun(ScriptRunSetup& setup, Lab& lab, ExecutionSink& sink, ExecutionControl& control)
      : setup_(setup),
        script_(*setup.script),
        file_(script_.name + ".lua"),
        lab_(lab),
        sink_(sink),
        control_(control),
        live_(setup.journal.empty()),
        label_(setup.initial_label),
        progress_(setup.initial_progress) {}

  asio::awaitable<RunOutcome> run() {
    std::exception_ptr unexpected;
    try {
      start_script();
      int nargs = 1;
      for (;;) {
        int nresults = 0;
        const int status = lua_resume(thread_, sandbox_->state(), nargs, &nresults);
        if (status == LUA_YIELD) {
          lua_pop(thread_, nresults);
          std::optional<int> next = co_await after_yield();
          if (!next) break;  // stopped, or failed at a lab call
          nargs = *next;
          continue;
        }
        if (status == LUA_OK) {
          finished(nresults);
        } else {
          failed_in_script();
        }
        break;
      }
    } catch (const Error& e) {
      failed_outside_script(e);
    } catch (const std::exception&) {
      // Not ours to classify (the execution records it as an internal failure), but the chart is still put back
      // first; a deliberate crash (not a std::exception) is left as it is, like the process it stands for.
      unexpected = std::current_exception();
    }
    // The run ends here (finished, failed or stopped): its last step is committed as each step before a lab call
    // is, without holding the io thread through the fsync (it held it up to 92 ms, docs/PERFORMANCE.md), and a disk
    // that refuses it suspends the run until there is room, so that the step is kept. A stop requested while it
    // waits ends the run as that stop, the step uncommitted (a resume measures it again).
    if (last_step_due_ && !unexpected) {
      try {
        co_await commit_pending_step();
      } catch (const Error& e) {
        if (e.cls() == ErrorClass::aborted && control_.requested()) {
          stop_for(control_);
        } else {
          failed_outside_script(e);
        }
      } catch (const std::exception&) {
        unexpected = std::current_exception();
      }
    }
    // Whatever the outcome: a script's own "put it back" step is not reached when it fails or stops mid-way.
    co_await lab_.put_back(state_);
    // Ended, however: what its calls kept is in its steps (or was no call's).
    lab_.forget_kept(control_.execution_id);
    if (unexpected) std::rethrow_exception(unexpected);
    co_return outcome_;
  }

  // LabCallSink: what the script does between two yields.
  bool is_campaign_thread(lua_State* L) const override { return L == thread_; }
  void request(std::string call, json args) override {
    requested_ = PendingCall{std::move(call), std::move(args)};
  }
  void record(const std::string& step, const json& fields) override {
    claim_step(recorded_, step);
    if (setup_.stored_steps.count(step)) return;  // committed before the interruption
    RecordedMeasurement m;
    m.step = step;
    m.quantity = fields["quantity"].get<std::string>();
    if (fields.contains("value") && fields["value"].is_number()) m.value = fields["value"].get<double>();
    m.unit = fields.value("unit", std::string());
    m.instrument_id = fields.value("instrument", std::string());
    auto instrument = lab_.instruments().find(m.instrument_id);
    m.simulated = instrument && instrument->identity().simulated;
    m.data = fields.contains("data") ? fields["data"] : json(nullptr);
    pending_.measurements.push_back(std::move(m));
  }
  void progress(double fraction, const std::string& label) override {
    progress_ = fraction;
    if (!label.empty()) label_ = label;
    // Replayed progress is already stored; only live progress makes a step worth committing.
    if (live_) progress_changed_ = true;
  }
  void log(const std::string& text) override { log::info(script_.name, text); }
  bool compute(const std::string& what, std::function<json()>& job) override {
    return handed_.take(setup_.compute, what, job);
  }

 private:
  void start_script() {
    sandbox_ = std::make_unique<LuaSandbox>(file_, script_.limits, setup_.random_seed);
    thread_ = start_run_thread(*sandbox_, script_, setup_.params, this);
  }

  // The script yielded: a slice of a long computation (resume it with nothing), or a lab call (resume
  // it with the answer). nullopt when the run ends here.
  asio::awaitable<std::optional<int>> after_yield() {
    if (handed_.pending()) {
      // The daemon serves while the worker pool runs it.
      auto resumed_with = handed_.run(setup_.compute, thread_);
      co_return co_await std::move(resumed_with);
    }
    if (sandbox_->take_slice_yield() && !requested_) {
      // A long computation between lab calls: let the daemon serve, then go on.
      co_await asio::post(co_await asio::this_coro::executor, asio::use_awaitable);
      if (control_.request == ExecutionControl::Request::abort || control_.request == ExecutionControl::Request::shutdown) {
        stop_for(control_);
        co_return std::nullopt;
      }
      co_return 0;
    }
    if (!requested_) throw Error(ErrorClass::script_error, file_ + ": coroutine.yield outside a coroutine of the script's own");
    PendingCall call = std::move(*std::exchange(requested_, std::nullopt));
    call.kind = kind_of(call.call);
    sandbox_->reset_budget();
    ++outcome_.calls;
    std::optional<json> result = answer_from_journal(call);
    if (!result) result = co_await perform_live(call);
    if (!result) co_return std::nullopt;
    push_json(thread_, *result);
    co_return 1;
  }

  // While the replay lasts, the journal answers (no instrument moves); the first call past it turns
  // the run live, and the lab is restored before that call. nullopt: the call is to be made live.
  std::optional<json> answer_from_journal(const PendingCall& c) {
    if (live_) return std::nullopt;
    if (c.kind == CallKind::control) return json(nullptr);  // a checkpoint inside the replayed part: already committed
    if (replay_index_ >= setup_.journal.size()) {
      live_ = true;
      restore_pending_ = true;
      return std::nullopt;
    }
    const auto& entry = setup_.journal[replay_index_];
    if (entry.call != c.call || entry.args != c.args) {
      throw Error(ErrorClass::script_error,
                  file_ + ":" + std::to_string(calling_line(thread_)) + ": replay diverged at lab call #" +
                      std::to_string(replay_index_) + ": the journal has lab." + entry.call + entry.args.dump() +
                      " but the script now calls lab." + c.call + c.args.dump(),
                  "the script is not deterministic (it must not depend on time, addresses or unordered "
                  "iteration); the run cannot resume");
    }
    ++replay_index_;
    ++outcome_.replayed;
    state_.apply(c.call, c.args, entry.result);
    timing_keys_.follow(c.call, c.args, entry.result);
    return entry.result;
  }

  // A live call: the step before it committed, the lab restored if the replay just ended, the call
  // made (waiting out what suspends it) and journaled. nullopt when the run stops or fails here.
  asio::awaitable<std::optional<json>> perform_live(const PendingCall& c) {
    if (control_.requested()) {
      stop_for(control_);
      co_return std::nullopt;
    }
    try {
      // A call's cost includes committing the step before it: the dry run adds up whole calls.
      const auto started = std::chrono::steady_clock::now();
      const bool storage_suspended = co_await commit_pending_step();
      bool restored_now = false;
      if (restore_pending_) {
        restored_now = true;
        if (!co_await restore_lab()) co_return std::nullopt;
      }
      json result;
      if (c.kind != CallKind::control) {
        // A restore or a wait for disk space is not what the call costs on a normal night.
        result = co_await perform_until_done(c, started, storage_suspended || restored_now);
        journal(c, result);
      }
      co_return result;
    } catch (const Error& e) {
      if (e.cls() == ErrorClass::aborted && control_.requested()) {
        stop_for(control_);
        co_return std::nullopt;
      }
      outcome_.kind = RunOutcome::Kind::failed;
      outcome_.error = e;
      outcome_.script_location = location(calling_line(thread_));
      last_step_due_ = true;
      co_return std::nullopt;
    }
  }

  // The step so far is whole (a lab call is next, or the run ends): commit it before anything moves. A disk that
  // refuses it suspends the execution until there is room; nothing is lost meanwhile. True if it suspended.
  asio::awaitable<bool> commit_pending_step() {
    bool storage_suspended = false;
    for (;;) {
      std::optional<Error> refused;
      try {
        co_await flush_awaiting();
      } catch (const Error& e) {
        if (e.cls() != ErrorClass::io_error) throw;
        refused = e;
      }
      if (!refused) break;
      if (!storage_suspended) {
        storage_suspended = true;
        log::warning(script_.name, std::string("suspended: storage: ") + refused->what());
        sink_.suspended(std::string("storage: ") + refused->what(), *refused);
      }
      co_await lab_.wait_retry(control_);
    }
    if (storage_suspended) sink_.resumed(json{{"condition", "storage"}});
    co_return storage_suspended;
  }

  // The first live call after a replay: the units checked to be the run's own, then the lab brought
  // to the state the replay says it should be in. False when another unit pauses the run.
  asio::awaitable<bool> restore_lab() {
    restore_pending_ = false;
    sink_.status_text("restoring the lab after a resume (step " + label_ + ")");
    if (setup_.verify_serials) {
      auto changed = co_await lab_.serial_mismatches(setup_.expected_serials);
      if (!changed.empty()) {
        std::string why = "another unit answers where the run's instrument was (";
        for (std::size_t i = 0; i < changed.size(); ++i) why += (i ? "; " : "") + changed[i];
        why += "): check it is the right instrument, then resume the execution to accept it";
        stop_for(ExecutionControl{ExecutionControl::Request::pause, why});
        co_return false;
      }
    }
    json actions = co_await lab_.restore(state_, control_);
    sink_.restored(actions);
    co_return true;
  }

  // Suspend, not fail: a condition that waiting mends stops the execution until it has cleared, then
  // the same call is made again (the interrupted step measured anew). Its time is learned only when
  // nothing interrupted it.
  asio::awaitable<json> perform_until_done(const PendingCall& c, std::chrono::steady_clock::time_point started,
                                           bool interrupted) {
    sink_.status_text(label_.empty() ? c.call : label_ + ": " + c.call);
    const std::string timing_key = timing_keys_.key(c.call, c.args);
    bool storage_waiting = false;
    for (;;) {
      std::optional<Error> failure;
      json result;
      try {
        result = co_await lab_.perform(c.call, c.args, control_);
      } catch (const Error& e) {
        failure = e;
      }
      if (!failure) {
        if (storage_waiting) sink_.resumed(json{{"condition", "storage"}});
        if (!interrupted) {
          const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
          const double lab_s = std::max(0.0, wall * lab_.time_scale() - TimingKeys::asked_wait_s(c.call, c.args));
          pending_.timings.push_back({timing_key, lab_s / TimingKeys::units(c.call, c.args)});
        }
        co_return result;
      }
      interrupted = true;
      if (failure->cls() == ErrorClass::io_error && !control_.requested()) {
        // The disk refused what the call keeps (a frame, a preview): wait for room as for a commit, then
        // make the call again. Announced once, so a long full disk does not fill the log as well.
        if (!storage_waiting) {
          storage_waiting = true;
          log::warning(script_.name, "suspended at " + c.call + ": storage: " + failure->what());
          sink_.suspended(std::string("storage: ") + failure->what(), *failure);
        }
        co_await lab_.wait_retry(control_);
        continue;
      }
      auto cause = Lab::suspend_cause(*failure);
      if (!cause || control_.requested()) throw *failure;
      std::string reason = *cause + ": " + failure->what();
      log::warning(script_.name, "suspended at " + c.call + ": " + reason);
      sink_.suspended(reason, *failure);
      json how = co_await lab_.await_recovery(c.call, c.args, *failure, control_);
      log::info(script_.name, "condition cleared (" + how.dump() + "); measuring the interrupted step again");
      sink_.resumed(how);
    }
  }

  // Into the step: the call and its answer, and the blobs the call kept, named in the run.
  void journal(const PendingCall& c, const json& result) {
    state_.apply(c.call, c.args, result);
    timing_keys_.follow(c.call, c.args, result);
    const auto seq = static_cast<std::int64_t>(replay_index_++);
    for (auto& b : lab_.take_kept(control_.execution_id)) {
      b.name = c.call + "#" + std::to_string(seq) + "/" + b.name;
      pending_.blobs.push_back(std::move(b));
    }
    pending_.journal.push_back(JournalEntry{seq, c.call, c.args, result});
  }

  void finished(int nresults) {
    outcome_.result = nresults > 0 ? to_json(thread_, -1, file_ + "'s result") : json(nullptr);
    outcome_.kind = RunOutcome::Kind::finished;
    progress(1.0, "done");
    last_step_due_ = true;
  }

  // A runtime error in the script (or a limit it hit). A script that knows what a person must do
  // says so: error{message = ..., hint = ..., class = "needs_operator"}.
  void failed_in_script() {
    std::string message = lua_tostring(thread_, -1) ? lua_tostring(thread_, -1) : "error object is not a string";
    ErrorInfo raised{ErrorClass::script_error, "", "fix the script and start a new run"};
    if (lua_istable(thread_, -1) && !sandbox_->killed()) {
      if (lua_getfield(thread_, -1, "message") == LUA_TSTRING) message = lua_tostring(thread_, -1);
      if (lua_getfield(thread_, -2, "hint") == LUA_TSTRING) raised.hint = lua_tostring(thread_, -1);
      if (lua_getfield(thread_, -3, "class") == LUA_TSTRING) {
        const std::string cls = lua_tostring(thread_, -1);
        // Only classes that describe the run's inputs or the lab's state: not ones the engine itself acts on
        // (io_error suspends, aborted ends quietly).
        for (auto c : {ErrorClass::needs_operator, ErrorClass::bad_parameter, ErrorClass::bad_data, ErrorClass::not_found}) {
          if (to_string(c) == cls) raised.cls = c;
        }
      }
      lua_pop(thread_, 3);
    }
    if (sandbox_->killed()) message = sandbox_->kill_reason();
    lua_State* L = sandbox_->state();
    luaL_traceback(L, thread_, nullptr, 0);
    std::string traceback = lua_tostring(L, -1) ? lua_tostring(L, -1) : "";
    lua_pop(L, 1);
    outcome_.kind = RunOutcome::Kind::failed;
    raised.message = message + " (step " + (label_.empty() ? "start" : label_) + ")";
    outcome_.error = Error(std::move(raised));
    outcome_.script_location = location(line_of(message, file_));
    outcome_.script_location["traceback"] = traceback;
    last_step_due_ = true;
  }

  void failed_outside_script(const Error& e) {
    outcome_.kind = RunOutcome::Kind::failed;
    outcome_.error = e;
    if (outcome_.script_location.is_null()) outcome_.script_location = location(line_of(e.info().message, file_));
    if (e.cls() == ErrorClass::io_error) {
      // The disk refused a commit: nothing half-stored; the run can go on once there is room.
      outcome_.kind = RunOutcome::Kind::suspended;
      outcome_.reason = std::string("storage: ") + e.what();
    }
  }

  // Stops at a safe point for a pause, abort or shutdown; what is pending is committed first.
  void stop_for(const ExecutionControl& c) {
    last_step_due_ = true;
    switch (c.request) {
      case ExecutionControl::Request::pause: outcome_.kind = RunOutcome::Kind::paused; break;
      case ExecutionControl::Request::abort: outcome_.kind = RunOutcome::Kind::aborted; break;
      default: outcome_.kind = RunOutcome::Kind::suspended; break;
    }
    outcome_.reason = c.reason;
  }

  // The step so far, committed off the daemon's io thread (the sink's commit_awaiting) while the io thread serves.
  asio::awaitable<void> flush_awaiting() {
    if (pending_.journal.empty() && pending_.measurements.empty() && !progress_changed_) co_return;
    pending_.progress = progress_;
    pending_.label = label_;
    co_await sink_.commit_awaiting(pending_);
    pending_ = StepCommit{};
    progress_changed_ = false;
  }

  json location(int line) const {
    return json{{"script", file_}, {"sha256", script_.sha256}, {"line", line}, {"step", label_}};
  }

  ScriptRunSetup& setup_;
  const CampaignScript& script_;
  const std::string file_;
  Lab& lab_;
  ExecutionSink& sink_;
  ExecutionControl& control_;
  RunOutcome outcome_;

  std::unique_ptr<LuaSandbox> sandbox_;
  lua_State* thread_ = nullptr;
  std::optional<PendingCall> requested_;  // what the script yielded with
  HandedComputation handed_;              // a computation the script handed over, for setup_.compute to run

  // The replay: where in the journal, the lab state it implies, what the calls' timing keys follow.
  bool live_;
  bool restore_pending_ = false;
  std::size_t replay_index_ = 0;
  LabState state_;
  TimingKeys timing_keys_;

  // The step since the last commit.
  StepCommit pending_;
  std::set<std::string> recorded_;
  std::string label_;
  double progress_ = 0;
  bool progress_changed_ = false;
  bool last_step_due_ = false;  // set where the run ends; run() commits the pending step then
};

}  // namespace

asio::awaitable<RunOutcome> run_campaign_script(ScriptRunSetup setup, Lab& lab, ExecutionSink& sink,
                                                ExecutionControl& control) {
  ScriptRun run(setup, lab, sink, control);
  co_return co_await run.run();
}

}  // namespace colorlab::campaigns
