#include "colorlab/campaigns/engine.hpp"

#include <chrono>
#include <regex>

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

class Engine final : public LabCallSink {
 public:
  explicit Engine(ScriptRunSetup& setup) : setup_(setup), label_(setup.initial_label), progress_(setup.initial_progress) {}

  bool is_campaign_thread(lua_State* L) const override { return L == thread_; }
  void request(std::string call, json args) override {
    pending_call_ = std::move(call);
    pending_args_ = std::move(args);
    has_request_ = true;
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
    m.data = fields.contains("data") ? fields["data"] : json(nullptr);
    pending_.measurements.push_back(std::move(m));
  }
  void progress(double fraction, const std::string& label) override {
    progress_ = fraction;
    if (!label.empty()) label_ = label;
    // Replayed progress is already stored; only live progress makes a step worth committing.
    if (live_) progress_changed_ = true;
  }
  void log(const std::string& text) override { log::info(setup_.script->name, text); }

  ScriptRunSetup& setup_;
  lua_State* thread_ = nullptr;
  bool has_request_ = false;
  std::string pending_call_;
  json pending_args_;
  std::set<std::string> recorded_;
  StepCommit pending_;
  std::string label_;
  double progress_ = 0;
  bool progress_changed_ = false;
  bool live_ = false;
};

}  // namespace

asio::awaitable<RunOutcome> run_campaign_script(ScriptRunSetup setup, Lab& lab, ExecutionSink& sink,
                                                ExecutionControl& control) {
  const CampaignScript& script = *setup.script;
  const std::string file = script.name + ".lua";
  RunOutcome outcome;
  Engine engine(setup);
  LabState state;
  TimingKeys timing_keys;
  std::size_t replay_index = 0;
  bool live = setup.journal.empty();
  engine.live_ = live;
  bool restore_pending = false;

  auto flush = [&] {
    if (engine.pending_.journal.empty() && engine.pending_.measurements.empty() && !engine.progress_changed_) return;
    engine.pending_.progress = engine.progress_;
    engine.pending_.label = engine.label_;
    sink.commit(engine.pending_);
    engine.pending_ = StepCommit{};
    engine.progress_changed_ = false;
  };
  auto location = [&](int line) {
    return json{{"script", file}, {"sha256", script.sha256}, {"line", line}, {"step", engine.label_}};
  };
  // Stops at a safe point for a pause, abort or shutdown; what is pending is committed first.
  auto stop_for = [&](const ExecutionControl& c) {
    flush();
    switch (c.request) {
      case ExecutionControl::Request::pause: outcome.kind = RunOutcome::Kind::paused; break;
      case ExecutionControl::Request::abort: outcome.kind = RunOutcome::Kind::aborted; break;
      default: outcome.kind = RunOutcome::Kind::suspended; break;
    }
    outcome.reason = c.reason;
  };

  try {
    LuaSandbox sandbox(file, script.limits, setup.random_seed);
    lua_State* L = sandbox.state();
    lua_State* thread = start_run_thread(sandbox, script, setup.params, &engine);
    engine.thread_ = thread;
    int nargs = 1;

    for (;;) {
      int nresults = 0;
      int status = lua_resume(thread, L, nargs, &nresults);
      if (status == LUA_YIELD) {
        lua_pop(thread, nresults);
        if (sandbox.take_slice_yield() && !engine.has_request_) {
          // A long computation between lab calls: let the daemon serve, then go on.
          co_await asio::post(co_await asio::this_coro::executor, asio::use_awaitable);
          if (control.request == ExecutionControl::Request::abort || control.request == ExecutionControl::Request::shutdown) {
            stop_for(control);
            break;
          }
          nargs = 0;
          continue;
        }
        if (!engine.has_request_) throw Error(ErrorClass::script_error, file + ": coroutine.yield outside a coroutine of the script's own");
        engine.has_request_ = false;
        sandbox.reset_budget();
        ++outcome.calls;
        const std::string call = engine.pending_call_;
        const json args = engine.pending_args_;
        const CallKind kind = kind_of(call);
        json result;
        bool answered = false;
        if (!live) {
          if (kind == CallKind::control) {
            answered = true;  // a checkpoint inside the replayed part: already committed
          } else if (replay_index < setup.journal.size()) {
            const auto& entry = setup.journal[replay_index];
            if (entry.call != call || entry.args != args) {
              throw Error(ErrorClass::script_error,
                          file + ":" + std::to_string(calling_line(thread)) + ": replay diverged at lab call #" +
                              std::to_string(replay_index) + ": the journal has lab." + entry.call + entry.args.dump() +
                              " but the script now calls lab." + call + args.dump(),
                          "the script is not deterministic (it must not depend on time, addresses or unordered "
                          "iteration); the run cannot resume");
            }
            result = entry.result;
            ++replay_index;
            ++outcome.replayed;
            state.apply(call, args, result);
            timing_keys.follow(call, args, result);
            answered = true;
          } else {
            live = true;
            engine.live_ = true;
            restore_pending = true;
          }
        }
        if (!answered) {
          if (control.requested()) {
            stop_for(control);
            break;
          }
          try {
            // The step before this call is whole: commit it before anything moves. A disk that
            // refuses it suspends the execution until there is room; nothing is lost meanwhile.
            // A call's cost includes committing the step before it: the dry run adds up whole calls.
            const auto call_started = std::chrono::steady_clock::now();
            bool storage_suspended = false;
            for (;;) {
              std::optional<Error> refused;
              try {
                flush();
              } catch (const Error& e) {
                if (e.cls() != ErrorClass::io_error) throw;
                refused = e;
              }
              if (!refused) break;
              if (!storage_suspended) {
                storage_suspended = true;
                log::warning(script.name, std::string("suspended: storage: ") + refused->what());
                sink.suspended(std::string("storage: ") + refused->what(), *refused);
              }
              co_await lab.wait_retry(control);
            }
            if (storage_suspended) sink.resumed(json{{"condition", "storage"}});
            bool restored_now = false;
            if (restore_pending) {
              restore_pending = false;
              restored_now = true;
              sink.status_text("restoring the lab after a resume (step " + engine.label_ + ")");
              if (setup.verify_serials) {
                auto changed = co_await lab.serial_mismatches(setup.expected_serials);
                if (!changed.empty()) {
                  std::string why = "another unit answers where the run's instrument was (";
                  for (std::size_t i = 0; i < changed.size(); ++i) why += (i ? "; " : "") + changed[i];
                  why += "): check it is the right instrument, then resume the execution to accept it";
                  ExecutionControl pause{ExecutionControl::Request::pause, why};
                  stop_for(pause);
                  break;
                }
              }
              json actions = co_await lab.restore(state, control);
              sink.restored(actions);
            }
            if (kind != CallKind::control) {
              sink.status_text(engine.label_.empty() ? call : engine.label_ + ": " + call);
              // Suspend, not fail: a condition that waiting mends stops the execution until it has
              // cleared, then the same call is made again (the interrupted step measured anew).
              const std::string timing_key = timing_keys.key(call, args);
              // A restore or a wait for disk space is not what the call costs on a normal night.
              bool interrupted = storage_suspended || restored_now;
              for (;;) {
                std::optional<Error> failure;
                try {
                  result = co_await lab.perform(call, args, control);
                } catch (const Error& e) {
                  failure = e;
                }
                if (!failure) {
                  if (!interrupted) {
                    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - call_started).count();
                    const double lab_s = std::max(0.0, wall * lab.time_scale() - TimingKeys::asked_wait_s(call, args));
                    engine.pending_.timings.push_back({timing_key, lab_s / TimingKeys::units(call, args)});
                  }
                  break;
                }
                interrupted = true;
                auto cause = Lab::suspend_cause(*failure);
                if (!cause || control.requested()) throw *failure;
                std::string reason = *cause + ": " + failure->what();
                log::warning(script.name, "suspended at " + call + ": " + reason);
                sink.suspended(reason, *failure);
                json how = co_await lab.await_recovery(call, *failure, control);
                log::info(script.name, "condition cleared (" + how.dump() + "); measuring the interrupted step again");
                sink.resumed(how);
              }
              state.apply(call, args, result);
              timing_keys.follow(call, args, result);
              engine.pending_.journal.push_back(JournalEntry{static_cast<std::int64_t>(replay_index), call, args, result});
              ++replay_index;
            }
          } catch (const Error& e) {
            if (e.cls() == ErrorClass::aborted && control.requested()) {
              stop_for(control);
              break;
            }
            outcome.kind = RunOutcome::Kind::failed;
            outcome.error = e;
            outcome.script_location = location(calling_line(thread));
            flush();
            break;
          }
        }
        push_json(thread, result);
        nargs = 1;
        continue;
      }
      if (status == LUA_OK) {
        outcome.result = nresults > 0 ? to_json(thread, -1, file + "'s result") : json(nullptr);
        outcome.kind = RunOutcome::Kind::finished;
        engine.progress(1.0, "done");
        flush();
        break;
      }
      // A runtime error in the script (or a limit it hit).
      std::string message = lua_tostring(thread, -1) ? lua_tostring(thread, -1) : "error object is not a string";
      // A script that knows what a person must do says so: error{message = ..., hint = ..., class = "needs_operator"}.
      ErrorInfo raised{ErrorClass::script_error, "", "fix the script and start a new run"};
      if (lua_istable(thread, -1) && !sandbox.killed()) {
        if (lua_getfield(thread, -1, "message") == LUA_TSTRING) message = lua_tostring(thread, -1);
        if (lua_getfield(thread, -2, "hint") == LUA_TSTRING) raised.hint = lua_tostring(thread, -1);
        if (lua_getfield(thread, -3, "class") == LUA_TSTRING) {
          const std::string cls = lua_tostring(thread, -1);
          // Only classes that describe the run's inputs or the lab's state: not ones the engine itself acts on
          // (io_error suspends, aborted ends quietly).
          for (auto c : {ErrorClass::needs_operator, ErrorClass::bad_parameter, ErrorClass::bad_data, ErrorClass::not_found}) {
            if (to_string(c) == cls) raised.cls = c;
          }
        }
        lua_pop(thread, 3);
      }
      if (sandbox.killed()) message = sandbox.kill_reason();
      luaL_traceback(L, thread, nullptr, 0);
      std::string traceback = lua_tostring(L, -1) ? lua_tostring(L, -1) : "";
      lua_pop(L, 1);
      outcome.kind = RunOutcome::Kind::failed;
      raised.message = message + " (step " + (engine.label_.empty() ? "start" : engine.label_) + ")";
      outcome.error = Error(std::move(raised));
      outcome.script_location = location(line_of(message, file));
      outcome.script_location["traceback"] = traceback;
      flush();
      break;
    }
  } catch (const Error& e) {
    outcome.kind = RunOutcome::Kind::failed;
    outcome.error = e;
    if (outcome.script_location.is_null()) outcome.script_location = location(line_of(e.info().message, file));
    if (e.cls() == ErrorClass::io_error) {
      // The disk refused a commit: nothing half-stored; the run can go on once there is room.
      outcome.kind = RunOutcome::Kind::suspended;
      outcome.reason = std::string("storage: ") + e.what();
    }
  }
  co_return outcome;
}

}  // namespace colorlab::campaigns
