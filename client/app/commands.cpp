#include "commands.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <set>
#include <iostream>
#include <thread>

#include "colorlab/client/api_client.hpp"
#include "colorlab/client/runs.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/protocol/states.hpp"
#include "client_support.hpp"
#include "follow.hpp"
#include "format.hpp"
#include "sequence_commands.hpp"

namespace colorlab::cli {

using nlohmann::json;

namespace {

// A query parameter's value, percent-encoded except RFC 3986's unreserved characters and the comma
// that separates a list of statuses.
std::string query_value(const std::string& v) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : v) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~' || c == ',') {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

struct RunOptions {
  std::string campaign;
  std::vector<std::string> params;
  bool detach = false;
  bool id_only = false;
  bool dry_run = false;
  bool small = false;
  std::string idempotency_key;
};

// A sequence: every step queued as one group, the queue started, the group followed to its end.
int run_sequence(const GlobalOptions& g, const RunOptions& o, const client::ApiClient& api) {
  if (o.dry_run) {
    throw Error(ErrorClass::bad_parameter, o.campaign + " is a sequence: a dry run goes step by step",
                "colorlab study " + o.campaign + " --dry-run" + (o.small ? " --small" : ""));
  }
  json group = queue_sequence(api, o.campaign, o.params, o.small, "stop", o.idempotency_key, true);
  if (!o.detach) group = follow_group(api, group, o.id_only || g.json);
  if (o.id_only) {
    for (const auto& run : group["run_ids"]) std::cout << run.get<std::string>() << "\n";
  } else {
    print(g, group, format_queue_group);
  }
  return o.detach || group["state"] == "done" ? 0 : 3;
}

int run_campaign(const GlobalOptions& g, const RunOptions& o) {
  auto api = make_client(g);
  if (names_sequence(api, o.campaign)) return run_sequence(g, o, api);
  if (o.small) throw Error(ErrorClass::bad_parameter, "--small is for a sequence; " + o.campaign + " is a campaign");
  json params = parse_params(o.params);
  if (o.dry_run) {
    json report = api.post("/v1/executions", {{"campaign", o.campaign}, {"params", params}, {"dry_run", true}});
    print(g, report, format_dry_run);
    return report.value("ok", false) ? 0 : 3;
  }
  std::map<std::string, std::string> headers;
  if (!o.idempotency_key.empty()) headers["Idempotency-Key"] = o.idempotency_key;
  json execution = api.post("/v1/executions", {{"campaign", o.campaign}, {"params", params}}, headers);
  std::string id = execution["id"];
  std::string run_id = execution["run_id"];
  if (o.detach) {
    if (o.id_only) {
      std::cout << run_id << "\n";
    } else {
      print(g, execution, format_execution);
    }
    return 0;
  }
  // Live by the event stream: progress and ETA, operator requests as they are posted, no polling.
  execution = follow_execution(api, execution, o.id_only || g.json);
  json run = client::fetch_run(api, run_id);
  bool ok = execution["status"] == "finished_ok";
  if (o.id_only) {
    std::cout << run_id << "\n";
    if (!ok) std::cerr << format_run(run);
  } else {
    print(g, run, format_run);
  }
  return ok ? 0 : 3;
}

}  // namespace

void add_daemon_commands(CLI::App& app, GlobalOptions& global) {
  auto* status = app.add_subcommand("status", "Show the daemon's version, API version and state");
  status->callback([&global] {
    auto client = make_client(global);
    json root = client.get("/v1");
    // A daemon that knows shipping says so (central and older daemons do not): one more local read, no network.
    const json features = root.value("features", json::array());
    if (std::find(features.begin(), features.end(), "shipping") != features.end()) root["shipping"] = client.get("/v1/shipping");
    print(global, root, format_status);
  });

  auto* instruments = app.add_subcommand("instruments", "List instruments, their state and whether they are simulated");
  instruments->callback([&global] { print(global, make_client(global).get("/v1/instruments"), format_instruments); });

  auto* campaigns = app.add_subcommand("campaigns", "List the campaigns the daemon can run and their parameters");
  campaigns->callback([&global] { print(global, make_client(global).get("/v1/campaigns"), format_campaigns); });

  auto run_opts = std::make_shared<RunOptions>();
  auto* run = app.add_subcommand("run", "Start a campaign (or queue a sequence's steps) and follow it to the end (exit 3 if it fails)");
  run->add_option("campaign", run_opts->campaign, "campaign or sequence name, e.g. luminance-spot, dissertation")->required();
  run->add_option("-p,--param", run_opts->params, "campaign parameter KEY=VALUE, a sequence's STEP.KEY=VALUE (repeatable)");
  run->add_flag("--small", run_opts->small, "a sequence's small variant (its `small` overrides)");
  run->add_flag("--detach", run_opts->detach, "return as soon as the campaign has started");
  run->add_flag("--id-only", run_opts->id_only, "print only the run id (for scripts)");
  run->add_flag("--dry-run", run_opts->dry_run,
                "check limits, instruments, disk and operator actions and estimate the duration; moves nothing (exit 3 on problems)");
  run->add_option("--idempotency-key", run_opts->idempotency_key, "retry-safe key: the same key never starts twice");
  run->callback([&global, run_opts] {
    int rc = run_campaign(global, *run_opts);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });

  auto limit = std::make_shared<unsigned>(20);
  auto cursor = std::make_shared<std::string>();
  auto* runs = app.add_subcommand("runs", "List stored runs, newest first");
  runs->add_option("--limit", *limit, "runs per page (1..300)");
  runs->add_option("--cursor", *cursor, "continue from a previous page");
  runs->callback([&global, limit, cursor] {
    std::string target = "/v1/runs?limit=" + std::to_string(*limit);
    if (!cursor->empty()) target += "&cursor=" + *cursor;
    print(global, make_client(global).get(target), format_runs);
  });

  auto exec_limit = std::make_shared<unsigned>(20);
  auto exec_cursor = std::make_shared<std::string>();
  auto exec_status = std::make_shared<std::string>();
  auto exec_campaign = std::make_shared<std::string>();
  auto* executions = app.add_subcommand("executions", "List executions, newest first (what ran, and how it ended)");
  executions->add_option("--status", *exec_status, "only these statuses, comma-separated (e.g. running,suspended)");
  executions->add_option("--campaign", *exec_campaign, "only this campaign");
  executions->add_option("--limit", *exec_limit, "executions per page (1..300)");
  executions->add_option("--cursor", *exec_cursor, "continue from a previous page");
  executions->callback([&global, exec_limit, exec_cursor, exec_status, exec_campaign] {
    std::string target = "/v1/executions?limit=" + std::to_string(*exec_limit);
    if (!exec_cursor->empty()) target += "&cursor=" + query_value(*exec_cursor);
    if (!exec_status->empty()) target += "&status=" + query_value(*exec_status);
    if (!exec_campaign->empty()) target += "&campaign=" + query_value(*exec_campaign);
    print(global, make_client(global).get(target), format_executions);
  });

  // Pause, resume and abort land at the campaign's next safe point (the step before is committed).
  for (const char* action : {"pause", "resume", "abort"}) {
    auto id = std::make_shared<std::string>();
    std::string help = std::string(action) == "pause"    ? "Pause a running execution at its next safe point"
                       : std::string(action) == "resume" ? "Resume a paused or suspended execution"
                                                         : "Abort an execution at its next safe point (its measurements stay)";
    auto* cmd = app.add_subcommand(action, help);
    cmd->add_option("execution", *id, "execution id (from `colorlab run --detach` or GET /v1/executions/{id})")->required();
    cmd->callback([&global, id, action = std::string(action)] {
      auto api = make_client(global);
      json e = api.post("/v1/executions/" + *id + "/" + action, json::object());
      // Pause and abort land at the campaign's next safe point: wait for it (a reading, a move) so
      // the answer says what the execution is now, not what it was.
      const std::string before = action == "resume" ? "paused" : "running";
      for (int i = 0; i < 600 && e.value("status", std::string()) == before; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        e = api.get("/v1/executions/" + *id);
      }
      print(global, e, format_execution);
    });
  }

  auto* requests = app.add_subcommand("requests", "List the operator requests campaigns are waiting for");
  requests->callback([&global] { print(global, make_client(global).get("/v1/requests"), format_requests); });

  auto request_id = std::make_shared<std::string>();
  auto answer = std::make_shared<std::string>();
  auto by = std::make_shared<std::string>("operator");
  auto* answer_cmd = app.add_subcommand("answer", "Answer an operator request (see `colorlab requests`)");
  answer_cmd->add_option("request", *request_id, "request id")->required();
  answer_cmd->add_option("option", *answer, "one of the request's options, e.g. done")->required();
  answer_cmd->add_option("--by", *by, "who answers (recorded with the run's events)");
  answer_cmd->callback([&global, request_id, answer, by] {
    json r = make_client(global).post("/v1/requests/" + *request_id, {{"answer", *answer}, {"by", *by}});
    print(global, r, format_request);
  });

  auto run_id = std::make_shared<std::string>();
  auto* show = app.add_subcommand("show", "Show one run with its measurements");
  show->add_option("run", *run_id, "run id")->required();
  show->callback([&global, run_id] { print(global, client::fetch_run(make_client(global), *run_id), format_run); });
}

}  // namespace colorlab::cli
