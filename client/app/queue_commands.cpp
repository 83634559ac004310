#include "queue_commands.hpp"

#include <map>
#include <memory>

#include "colorlab/core/error.hpp"
#include "client_support.hpp"
#include "format.hpp"
#include "sequence_commands.hpp"

namespace colorlab::cli {

using nlohmann::json;

namespace {

struct AddOptions {
  std::string campaign;
  std::vector<std::string> params;
  std::string on_failure = "stop";
  std::string idempotency_key;
  bool small = false;
};

}  // namespace

void add_queue_commands(CLI::App& app, GlobalOptions& global) {
  auto* queue = app.add_subcommand("queue", "The night's queue: campaigns that run one after another, across restarts");
  queue->require_subcommand(1);

  auto add_opts = std::make_shared<AddOptions>();
  auto* add = queue->add_subcommand("add", "Append a campaign to the queue (its parameters are checked now)");
  add->add_option("campaign", add_opts->campaign, "campaign or sequence name, e.g. luminance-spot, dissertation")->required();
  add->add_option("-p,--param", add_opts->params, "campaign parameter KEY=VALUE, a sequence's STEP.KEY=VALUE (repeatable)");
  add->add_flag("--small", add_opts->small, "a sequence's small variant (its `small` overrides)");
  add->add_option("--on-failure", add_opts->on_failure, "if it fails: stop the queue, or continue with the next item")
      ->check(CLI::IsMember({"stop", "continue"}))
      ->capture_default_str();
  add->add_option("--idempotency-key", add_opts->idempotency_key, "retry-safe key: the same key never queues twice");
  add->callback([&global, add_opts] {
    auto api = make_client(global);
    if (names_sequence(api, add_opts->campaign)) {
      // Every step at once, as one group; each reference filled in when its step comes up.
      print(global,
            queue_sequence(api, add_opts->campaign, add_opts->params, add_opts->small, add_opts->on_failure,
                           add_opts->idempotency_key, false),
            format_queue_group);
      return;
    }
    if (add_opts->small) {
      throw Error(ErrorClass::bad_parameter, "--small is for a sequence; " + add_opts->campaign + " is a campaign");
    }
    std::map<std::string, std::string> headers;
    if (!add_opts->idempotency_key.empty()) headers["Idempotency-Key"] = add_opts->idempotency_key;
    json body{
        {"campaign", add_opts->campaign},
        {"params", parse_params(add_opts->params)},
        {"on_failure", add_opts->on_failure},
    };
    print(global, api.post("/v1/queue", body, headers), format_queue_item);
  });

  auto history = std::make_shared<unsigned>(10);
  auto* list = queue->add_subcommand("list", "Show the queue: its state, the running item, the queued ones, the recent ones");
  list->add_option("--history", *history, "how many ended items to show (0..300)")->capture_default_str();
  list->callback([&global, history] {
    print(global, make_client(global).get("/v1/queue?history=" + std::to_string(*history)), format_queue);
  });

  auto remove_id = std::make_shared<std::string>();
  auto* remove = queue->add_subcommand("remove", "Take a queued item out of the queue (a running one: colorlab abort)");
  remove->add_option("id", *remove_id, "queue item id (from colorlab queue list)")->required();
  remove->callback([&global, remove_id] {
    print(global, make_client(global).del("/v1/queue/" + *remove_id), format_queue_item);
  });

  auto move_id = std::make_shared<std::string>();
  auto position = std::make_shared<long>(1);
  auto* move = queue->add_subcommand("move", "Put a queued item at another position (1 runs next)");
  move->add_option("id", *move_id, "queue item id")->required();
  move->add_option("position", *position, "new position among the queued items, 1 = next")->required();
  move->callback([&global, move_id, position] {
    print(global, make_client(global).post("/v1/queue/" + *move_id + "/move", {{"position", *position}}), format_queue_item);
  });

  auto* start = queue->add_subcommand("start", "Start the queue: the next item runs as soon as no execution is active");
  start->callback([&global] { print(global, make_client(global).post("/v1/queue/start", json::object()), format_queue); });

  auto* stop = queue->add_subcommand("stop", "Stop the queue after the running item (which is not aborted)");
  stop->callback([&global] { print(global, make_client(global).post("/v1/queue/stop", json::object()), format_queue); });
}

}  // namespace colorlab::cli
