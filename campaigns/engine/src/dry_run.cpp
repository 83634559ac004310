#include "colorlab/campaigns/dry_run.hpp"

#include <algorithm>
#include <chrono>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <system_error>
#include <utility>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/this_coro.hpp>
#include <boost/asio/use_awaitable.hpp>
#include <boost/asio/use_future.hpp>
#include <lua5.4/lua.hpp>

#include "colorlab/campaigns/dry_lab.hpp"
#include "colorlab/campaigns/lab_api.hpp"
#include "colorlab/campaigns/lab_calls.hpp"
#include "colorlab/campaigns/lua_sandbox.hpp"
#include "colorlab/campaigns/lua_value.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/campaigns/roles.hpp"
#include "run_thread.hpp"

namespace colorlab::campaigns {

namespace asio = boost::asio;
using nlohmann::json;

namespace {

struct KeyCost {
  std::int64_t calls = 0;
  double lab_seconds = 0;
  std::string source;  // "measured" or "assumed"
  std::int64_t n = 0;  // timings it was learned from
};

// Bytes a stored step costs beyond its JSON text: row headers, indexes, the WAL's copy.
constexpr double kStorageOverhead = 3.0;

const InstrumentSet& no_instruments() {
  static const InstrumentSet none;
  return none;
}

// One dry run: the script run call by call against the model of the lab, then the report. run()
// reads top to bottom; the script's records (for the storage estimate) and lab calls come in
// through LabCallSink as in a real run.
class DryRun final : public LabCallSink {
 public:
  explicit DryRun(const DryRunSetup& setup)
      : setup_(setup),
        script_(*setup.script),
        file_(script_.name + ".lua"),
        instruments_(setup.instruments ? *setup.instruments : no_instruments()),
        lab_(instruments_, setup.runs),
        roles_(script_.needs.begin(), script_.needs.end()) {}

  asio::awaitable<json> run() {
    co_await run_script();
    json instruments = instruments_report();
    json storage = storage_report();
    co_return report(std::move(instruments), std::move(storage));
  }

  bool is_campaign_thread(lua_State* L) const override { return L == thread_; }
  void request(std::string c, json a) override { requested_ = std::make_pair(std::move(c), std::move(a)); }
  void record(const std::string& step, const json& fields) override {
    claim_step(steps_, step);
    record_bytes_ += step.size() + fields.dump().size();
  }
  void progress(double, const std::string&) override {}
  void log(const std::string&) override {}
  bool compute(const std::string& what, std::function<json()>& job) override {
    return handed_.take(setup_.compute, what, job);
  }

 private:
  // The script from start to end (or to the first thing that stops a real run), every lab call
  // answered by the model and costed.
  asio::awaitable<void> run_script() {
    LuaSandbox sandbox(file_, script_.limits, 1);
    sandbox_ = &sandbox;
    thread_ = start_run_thread(sandbox, script_, setup_.params, this);
    int nargs = 1;
    for (;;) {
      int nresults = 0;
      const auto resumed = std::chrono::steady_clock::now();
      const int status = lua_resume(thread_, sandbox.state(), nargs, &nresults);
      script_wall_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - resumed).count();
      if (status == LUA_YIELD) {
        lua_pop(thread_, nresults);
        std::optional<int> next = co_await after_yield();
        if (!next) break;
        nargs = *next;
        continue;
      }
      if (status == LUA_OK) {
        finished_ = true;
        break;
      }
      std::string message = lua_tostring(thread_, -1) ? lua_tostring(thread_, -1) : "error object is not a string";
      if (sandbox.killed()) message = sandbox.kill_reason();
      problems_.push_back({"script", message});
      stopped_at_ = json{{"line", line_of(message, file_)}};
      break;
    }
    sandbox_ = nullptr;
  }

  // What the script yielded with: nothing (a slice of a long computation), a checkpoint, or a lab
  // call answered by the model. How many values to resume it with; nullopt where the dry run stops.
  asio::awaitable<std::optional<int>> after_yield() {
    if (handed_.pending()) {
      // An analysis on the daemon's worker pool: its time is the script's own, as if inline.
      const auto started = std::chrono::steady_clock::now();
      auto resumed_with = handed_.run(setup_.compute, thread_);
      const int values = co_await std::move(resumed_with);
      script_wall_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      co_return values;
    }
    if (sandbox_->take_slice_yield() && !requested_) {
      // A long stretch of the script's own computation: on the daemon, let it serve meanwhile.
      if (setup_.compute) co_await asio::post(co_await asio::this_coro::executor, asio::use_awaitable);
      co_return 0;
    }
    co_return answer_call();
  }

  // A checkpoint, or a lab call answered by the model.
  std::optional<int> answer_call() {
    if (!requested_) throw Error(ErrorClass::script_error, file_ + ": coroutine.yield outside a coroutine of the script's own");
    const auto [call, args] = std::move(*std::exchange(requested_, std::nullopt));
    sandbox_->reset_budget();
    if (kind_of(call) == CallKind::control) return 0;
    if (++calls_ > static_cast<std::int64_t>(setup_.max_calls)) {
      return stop_at(call, "script",
                     "the dry run stopped after " + std::to_string(setup_.max_calls) +
                         " lab calls: the script may wait for a reading the dry run cannot predict");
    }
    const std::string role = DryLab::role_of(call);
    if (!role.empty()) roles_.insert(role);
    // What the call costs: the script's own waits exactly, the rest as this lab's calls have cost.
    const std::string key = keys_.key(call, args);
    std::optional<double> seconds = cost_of(call, args, key);
    if (!seconds) return std::nullopt;
    json result;
    try {
      result = lab_.answer(call, args, lab_s_, problems_);
    } catch (const Error& e) {
      return stop_at(call, "call", e.info().message + (e.info().hint.empty() ? "" : " (" + e.info().hint + ")"));
    }
    const LabCall* row = find_lab_call(call);
    if (row && row->timing.lamps == LampEffect::settle && result.is_object()) result["waited_s"] = *seconds;
    lab_s_ += *seconds;
    keys_.follow(call, args, result);
    journal_bytes_ += call.size() + args.dump().size() + result.dump().size();
    push_json(thread_, result);
    return 1;
  }

  // The call's lab seconds: what the script asked to wait, plus per unit what this lab's calls under
  // the same key cost (or the nominal figure, or a person's timeout), added to the key's tally.
  // nullopt where the call stops the dry run (an operator request it cannot read).
  std::optional<double> cost_of(const std::string& call, const json& args, const std::string& key) {
    double seconds = TimingKeys::asked_wait_s(call, args);
    KeyCost& cost = by_key_[key];
    ++cost.calls;
    double per_unit = 0;
    bool person = false;
    if (call == "operator.request") {
      OperatorRequest r;
      try {
        r = parse_operator_request(args[0]);
      } catch (const Error& e) {
        stop_at(call, "script", e.info().message);
        return std::nullopt;
      }
      person = !(setup_.hands && setup_.hands->can_perform(r.action));
      note_operator_action(r, person);
      if (person) {
        // Nobody can say when a person answers; at worst the default is taken at the timeout.
        per_unit = r.timeout_s;
        operator_wait_s_ += r.timeout_s;
      }
    }
    if (!person) {
      if (auto t = setup_.timings.find(key); t != setup_.timings.end() && t->second.n > 0) {
        per_unit = t->second.mean_s;
        cost.source = "measured";
        cost.n = t->second.n;
      } else {
        per_unit = nominal_lab_seconds(key, setup_.options);
        if (cost.source.empty()) cost.source = "assumed";
      }
    } else {
      cost.source = "operator timeout";
    }
    const double call_s = per_unit * TimingKeys::units(call, args);
    seconds += call_s;
    if (cost.source != "measured") assumed_s_ += call_s;
    if (TimingKeys::warms_up(call, key)) ++warmups_;
    cost.lab_seconds += seconds;
    return seconds;
  }

  void note_operator_action(const OperatorRequest& r, bool person) {
    json& a = operator_actions_[r.action];
    if (a.is_null()) {
      action_order_.push_back(r.action);
      a = json{
          {"action", r.action},
          {"prompt", r.prompt},
          {"count", 0},
          {"options", r.options},
          {"default", r.default_option},
          {"timeout_s", r.timeout_s},
          {"by", person ? "operator" : "simulated lab"},
      };
    }
    a["count"] = a["count"].get<int>() + 1;
  }

  std::optional<int> stop_at(const std::string& call, const std::string& kind, const std::string& message) {
    problems_.push_back({kind, message});
    stopped_at_ = json{{"line", calling_line(thread_)}, {"call", call}};
    return std::nullopt;
  }

  // Every role the script declared or called on: the instrument that would serve it, or the problem.
  json instruments_report() {
    json instruments = json::array();
    for (const auto& role : roles_) {
      auto i = lab_.instrument_for(role);
      if (!i) {
        auto absent = absent_for(instruments_, role);
        problems_.push_back({"instrument", "the campaign needs " + role_words(role) +
                                               (absent.empty() ? ", and none is configured" : ", and it is not here: " + absent)});
        instruments.push_back({{"role", role}, {"instrument", nullptr}});
        continue;
      }
      json entry{{"role", role},
                 {"instrument", i->id()},
                 {"state", std::string(drivers::to_string(i->state()))},
                 {"simulated", i->identity().simulated}};
      if (auto reason = InstrumentSet::absence(*i)) {
        entry["state"] = "absent";
        entry["reason"] = *reason;
        if (InstrumentSet::port_missing(*i)) {
          problems_.push_back({"instrument", "the campaign needs " + role_words(role) + ", and it is not here: '" +
                                                 i->id() + "' is configured but absent: " + *reason});
        }
      }
      instruments.push_back(std::move(entry));
    }
    return instruments;
  }

  // What the run's journal and measurements take, against the free space where they go.
  json storage_report() {
    json storage{{"estimated_bytes", static_cast<std::int64_t>((journal_bytes_ + record_bytes_) * kStorageOverhead)}};
    if (setup_.state_dir.empty()) return storage;
    std::error_code ec;
    auto space = std::filesystem::space(setup_.state_dir, ec);
    if (ec) return storage;
    storage["available_bytes"] = static_cast<std::int64_t>(space.available);
    if (storage["estimated_bytes"].get<double>() > static_cast<double>(space.available)) {
      problems_.push_back({"storage", "the run needs about " + std::to_string(storage["estimated_bytes"].get<std::int64_t>()) +
                                          " bytes and " + setup_.state_dir.string() + " has " +
                                          std::to_string(space.available) + " free"});
    }
    return storage;
  }

  json report(json instruments, json storage) {
    json problem_list = json::array();
    for (const auto& p : problems_) problem_list.push_back({{"kind", p.kind}, {"message", p.message}});
    json keys_json = json::array();
    for (const auto& [key, c] : by_key_) {
      json k{{"key", key}, {"calls", c.calls}, {"lab_seconds", c.lab_seconds}, {"source", c.source}};
      if (c.n) k["n"] = c.n;
      keys_json.push_back(k);
    }
    std::sort(keys_json.begin(), keys_json.end(),
              [](const json& a, const json& b) { return a["lab_seconds"].get<double>() > b["lab_seconds"].get<double>(); });
    json actions = json::array();
    for (const auto& a : action_order_) actions.push_back(operator_actions_[a]);

    // The script's own computation (analyses included) runs at the machine's speed, not the lab's.
    const double scale = setup_.options.time_scale > 0 ? setup_.options.time_scale : 1.0;
    const double wall_s = lab_s_ / scale + script_wall_s_;
    json report{{"campaign", script_.name}, {"params", setup_.params}};
    report["ok"] = problems_.empty() && finished_;
    report["finished"] = finished_;
    report["problems"] = problem_list;
    if (!stopped_at_.is_null()) report["stopped_at"] = stopped_at_;
    report["calls"] = calls_;
    report["measurements"] = steps_.size();
    report["instruments"] = std::move(instruments);
    report["operator_actions"] = actions;
    report["lamp_warmups"] = warmups_;
    report["estimate"] = json{{"lab_seconds", lab_s_ + script_wall_s_ * scale},
                              {"wall_seconds", wall_s},
                              {"time_scale", scale},
                              {"measured_share", lab_s_ > 0 ? 1.0 - assumed_s_ / lab_s_ : 1.0},
                              {"operator_wait_s", operator_wait_s_},
                              {"script_wall_s", script_wall_s_},
                              {"by_key", keys_json}};
    report["storage"] = std::move(storage);
    return report;
  }

  const DryRunSetup& setup_;
  const CampaignScript& script_;
  const std::string file_;
  const InstrumentSet& instruments_;
  DryLab lab_;
  LuaSandbox* sandbox_ = nullptr;  // while run_script runs
  lua_State* thread_ = nullptr;
  std::optional<std::pair<std::string, json>> requested_;  // the lab call the script yielded with
  // a computation the script handed over, for setup_.compute to run
  HandedComputation handed_;

  TimingKeys keys_;
  std::vector<DryProblem> problems_;
  std::map<std::string, KeyCost> by_key_;
  std::map<std::string, json> operator_actions_;
  std::vector<std::string> action_order_;
  std::set<std::string> roles_;
  std::set<std::string> steps_;
  std::size_t record_bytes_ = 0;
  double lab_s_ = 0, operator_wait_s_ = 0, assumed_s_ = 0, script_wall_s_ = 0;
  std::int64_t calls_ = 0, warmups_ = 0;
  std::size_t journal_bytes_ = 0;
  json stopped_at_ = nullptr;
  bool finished_ = false;
};

}  // namespace

double nominal_lab_seconds(const std::string& key, const LabOptions& options) {
  // A stability window is readings of the luminance meter until the window is full.
  const auto& c = options.warmup;
  const double window_s =
      c.window_s + (c.window_s / std::max(c.interval_s, 1e-3) + 1) * TimingKeys::nominal_s("meter.measure", 0, 0);
  return TimingKeys::nominal_s(key, options.lamp_warmup_s, window_s);
}

json dry_run_campaign(const DryRunSetup& setup) {
  // No executor of the caller's: the dry run's own, for its (then inline) computations.
  asio::io_context io;
  DryRunSetup inline_setup = setup;
  inline_setup.compute = nullptr;
  auto result = asio::co_spawn(io, dry_run_campaign_async(std::move(inline_setup)), asio::use_future);
  io.run();
  return result.get();
}

asio::awaitable<json> dry_run_campaign_async(DryRunSetup setup) {
  DryRun run(setup);
  // The awaitable first, then co_await it: no temporaries in the co_await expression (GCC 12).
  auto pending = run.run();
  co_return co_await std::move(pending);
}

}  // namespace colorlab::campaigns
