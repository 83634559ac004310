#include "colorlab/campaigns/dry_run.hpp"

#include <algorithm>
#include <chrono>
#include <map>
#include <set>
#include <system_error>

#include <lua5.4/lua.hpp>

#include "colorlab/campaigns/lab_api.hpp"
#include "colorlab/campaigns/lua_sandbox.hpp"
#include "colorlab/campaigns/lua_value.hpp"
#include "colorlab/core/error.hpp"
#include "dry_run_answers.hpp"
#include "roles.hpp"
#include "run_thread.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

namespace {

// What the script does besides lab calls: records (for the storage estimate) and progress.
class DrySink final : public LabCallSink {
 public:
  bool is_campaign_thread(lua_State* L) const override { return L == thread; }
  void request(std::string c, json a) override {
    call = std::move(c);
    args = std::move(a);
    has_request = true;
  }
  void record(const std::string& step, const json& fields) override {
    claim_step(steps, step);
    record_bytes += step.size() + fields.dump().size();
  }
  void progress(double, const std::string&) override {}
  void log(const std::string&) override {}

  lua_State* thread = nullptr;
  bool has_request = false;
  std::string call;
  json args;
  std::set<std::string> steps;
  std::size_t record_bytes = 0;
};

struct KeyCost {
  std::int64_t calls = 0;
  double lab_seconds = 0;
  std::string source;  // "measured" or "assumed"
  std::int64_t n = 0;  // timings it was learned from
};

// Bytes a stored step costs beyond its JSON text: row headers, indexes, the WAL's copy.
constexpr double kStorageOverhead = 3.0;

}  // namespace

double nominal_lab_seconds(const std::string& key, const LabOptions& options) {
  // Assumed figures for calls this lab has never timed, on the long side (an estimate that is too
  // short ruins a night, one too long only starts it earlier). Argyll's timeouts bound the
  // Spectrolino's (measure ≤ 12 s, move ≤ 10 s); the rest are a few exchanges on a serial line.
  if (key.rfind("wait_stable cold", 0) == 0) return options.lamp_warmup_s;
  if (key == "wait_stable warm") {
    const auto& c = options.warmup;
    return c.window_s + (c.window_s / std::max(c.interval_s, 1e-3) + 1) * nominal_lab_seconds("meter.measure", options);
  }
  if (key == "meter.measure") return 1.0;
  if (key == "table.read_patch" || key == "table.measure_at" || key == "spectro.measure") return 3.0;
  if (key == "spectro.calibrate") return 6.0;
  if (key == "table.move" || key == "table.home") return 3.0;
  if (key.rfind("table.", 0) == 0) return 0.5;
  if (key.rfind("lamps.", 0) == 0 || key == "spectro.mode") return 0.2;
  if (key == "dimmer.set") return 0.5;
  if (key == "camera.configure") return 0.5;
  if (key.rfind("camera.", 0) == 0) return 1.5;  // per frame (and format): exposure, transfer, decode
  if (key.rfind("operator.request", 0) == 0) return 1.0;  // the simulated lab's hands; a person: the timeout
  return 0.0;  // wait (its time is exact), now, lamps.names, runs.*, checkpoint
}

json dry_run_campaign(const DryRunSetup& setup) {
  const CampaignScript& script = *setup.script;
  const std::string file = script.name + ".lua";
  const double scale = setup.options.time_scale > 0 ? setup.options.time_scale : 1.0;
  static const InstrumentSet no_instruments;
  DryLab lab(setup.instruments ? *setup.instruments : no_instruments, setup.runs);
  DrySink sink;
  TimingKeys keys;
  std::vector<DryProblem> problems;
  std::map<std::string, KeyCost> by_key;
  std::map<std::string, json> operator_actions;
  std::vector<std::string> action_order;
  std::set<std::string> roles(script.needs.begin(), script.needs.end());
  double lab_s = 0, operator_wait_s = 0, assumed_s = 0, script_wall_s = 0;
  std::int64_t calls = 0, warmups = 0;
  std::size_t journal_bytes = 0;
  json stopped_at = nullptr;
  json report{{"campaign", script.name}, {"params", setup.params}};

  LuaSandbox sandbox(file, script.limits, 1);
  lua_State* L = sandbox.state();
  lua_State* thread = start_run_thread(sandbox, script, setup.params, &sink);
  sink.thread = thread;
  int nargs = 1;
  bool finished = false;
  for (;;) {
    int nresults = 0;
    const auto resumed = std::chrono::steady_clock::now();
    const int status = lua_resume(thread, L, nargs, &nresults);
    script_wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - resumed).count();
    if (status == LUA_YIELD) {
      lua_pop(thread, nresults);
      if (sandbox.take_slice_yield() && !sink.has_request) {
        nargs = 0;
        continue;
      }
      if (!sink.has_request) throw Error(ErrorClass::script_error, file + ": coroutine.yield outside a coroutine of the script's own");
      sink.has_request = false;
      sandbox.reset_budget();
      const std::string call = sink.call;
      const json args = sink.args;
      if (kind_of(call) == CallKind::control) {
        nargs = 0;
        continue;
      }
      if (++calls > static_cast<std::int64_t>(setup.max_calls)) {
        problems.push_back({"script", "the dry run stopped after " + std::to_string(setup.max_calls) +
                                          " lab calls: the script may wait for a reading the dry run cannot predict"});
        stopped_at = json{{"line", calling_line(thread)}, {"call", call}};
        break;
      }
      const std::string role = DryLab::role_of(call);
      if (!role.empty()) roles.insert(role);
      // What the call costs: the script's own waits exactly, the rest as this lab's calls have cost.
      const std::string key = keys.key(call, args);
      double seconds = TimingKeys::asked_wait_s(call, args);
      KeyCost& cost = by_key[key];
      ++cost.calls;
      double per_unit = 0;
      bool person = false;
      if (call == "operator.request") {
        OperatorRequest r;
        try {
          r = parse_operator_request(args[0]);
        } catch (const Error& e) {
          problems.push_back({"script", e.info().message});
          stopped_at = json{{"line", calling_line(thread)}, {"call", call}};
          break;
        }
        person = !(setup.hands && setup.hands->can_perform(r.action));
        json& a = operator_actions[r.action];
        if (a.is_null()) {
          action_order.push_back(r.action);
          a = json{{"action", r.action}, {"prompt", r.prompt}, {"count", 0}, {"options", r.options},
                   {"default", r.default_option}, {"timeout_s", r.timeout_s}, {"by", person ? "operator" : "simulated lab"}};
        }
        a["count"] = a["count"].get<int>() + 1;
        if (person) {
          // Nobody can say when a person answers; at worst the default is taken at the timeout.
          per_unit = r.timeout_s;
          operator_wait_s += r.timeout_s;
        }
      }
      if (!person) {
        if (auto t = setup.timings.find(key); t != setup.timings.end() && t->second.n > 0) {
          per_unit = t->second.mean_s;
          cost.source = "measured";
          cost.n = t->second.n;
        } else {
          per_unit = nominal_lab_seconds(key, setup.options);
          if (cost.source.empty()) cost.source = "assumed";
        }
      } else {
        cost.source = "operator timeout";
      }
      const double call_s = per_unit * TimingKeys::units(call, args);
      seconds += call_s;
      if (cost.source != "measured") assumed_s += call_s;
      if (call == "wait_stable" && key != "wait_stable warm") ++warmups;
      cost.lab_seconds += seconds;
      json result;
      try {
        result = lab.answer(call, args, lab_s, problems);
      } catch (const Error& e) {
        problems.push_back({"call", e.info().message + (e.info().hint.empty() ? "" : " (" + e.info().hint + ")")});
        stopped_at = json{{"line", calling_line(thread)}, {"call", call}};
        break;
      }
      if (call == "wait_stable" && result.is_object()) result["waited_s"] = seconds;
      lab_s += seconds;
      keys.follow(call, args, result);
      journal_bytes += call.size() + args.dump().size() + result.dump().size();
      push_json(thread, result);
      nargs = 1;
      continue;
    }
    if (status == LUA_OK) {
      finished = true;
      break;
    }
    std::string message = lua_tostring(thread, -1) ? lua_tostring(thread, -1) : "error object is not a string";
    if (sandbox.killed()) message = sandbox.kill_reason();
    problems.push_back({"script", message});
    stopped_at = json{{"line", line_of(message, file)}};
    break;
  }

  // Instruments: every role the script declared or called on.
  json instruments = json::array();
  for (const auto& role : roles) {
    auto i = lab.instrument_for(role);
    if (!i) {
      auto absent = absent_for(setup.instruments ? *setup.instruments : no_instruments, role);
      problems.push_back({"instrument", "the campaign needs " + role_words(role) +
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
        problems.push_back({"instrument", "the campaign needs " + role_words(role) + ", and it is not here: '" +
                                              i->id() + "' is configured but absent: " + *reason});
      }
    }
    instruments.push_back(std::move(entry));
  }

  // Storage: what the run's journal and measurements take, against the free space where they go.
  json storage{{"estimated_bytes", static_cast<std::int64_t>((journal_bytes + sink.record_bytes) * kStorageOverhead)}};
  if (!setup.state_dir.empty()) {
    std::error_code ec;
    auto space = std::filesystem::space(setup.state_dir, ec);
    if (!ec) {
      storage["available_bytes"] = static_cast<std::int64_t>(space.available);
      if (storage["estimated_bytes"].get<double>() > static_cast<double>(space.available)) {
        problems.push_back({"storage", "the run needs about " + std::to_string(storage["estimated_bytes"].get<std::int64_t>()) +
                                           " bytes and " + setup.state_dir.string() + " has " +
                                           std::to_string(space.available) + " free"});
      }
    }
  }

  json problem_list = json::array();
  for (const auto& p : problems) problem_list.push_back({{"kind", p.kind}, {"message", p.message}});
  json keys_json = json::array();
  for (const auto& [key, c] : by_key) {
    json k{{"key", key}, {"calls", c.calls}, {"lab_seconds", c.lab_seconds}, {"source", c.source}};
    if (c.n) k["n"] = c.n;
    keys_json.push_back(k);
  }
  std::sort(keys_json.begin(), keys_json.end(),
            [](const json& a, const json& b) { return a["lab_seconds"].get<double>() > b["lab_seconds"].get<double>(); });
  json actions = json::array();
  for (const auto& a : action_order) actions.push_back(operator_actions[a]);

  // The script's own computation (analyses included) runs at the machine's speed, not the lab's.
  const double wall_s = lab_s / scale + script_wall_s;
  report["ok"] = problems.empty() && finished;
  report["finished"] = finished;
  report["problems"] = problem_list;
  if (!stopped_at.is_null()) report["stopped_at"] = stopped_at;
  report["calls"] = calls;
  report["measurements"] = sink.steps.size();
  report["instruments"] = instruments;
  report["operator_actions"] = actions;
  report["lamp_warmups"] = warmups;
  report["estimate"] = json{{"lab_seconds", lab_s + script_wall_s * scale},
                            {"wall_seconds", wall_s},
                            {"time_scale", scale},
                            {"measured_share", lab_s > 0 ? 1.0 - assumed_s / lab_s : 1.0},
                            {"operator_wait_s", operator_wait_s},
                            {"script_wall_s", script_wall_s},
                            {"by_key", keys_json}};
  report["storage"] = storage;
  return report;
}

}  // namespace colorlab::campaigns
