#pragma once
// Operator requests: the things only a person can do on a real bench (aim the meter at a spot,
// load the chart, put the white tile in place). A campaign asks with lab.operator.request; the
// request waits for an answer through the API or the CLI and takes its default when its time is
// up, so an unattended night never stops on an unanswered question. Where something else can do
// the action — the simulated lab aims its meter through its control channel — `OperatorHands`
// does it and nobody waits. The desk lives on the daemon's io_context thread: no locks.
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/awaitable.hpp>
#include <nlohmann/json.hpp>

namespace colorlab::campaigns {

struct OperatorRequest {
  std::string id;  // UUIDv7
  std::string execution_id;
  std::string action;  // "aim_meter", "load_chart", "white_tile", "confirm", or the script's own word
  std::string prompt;  // what to do, in words for a person
  std::vector<std::string> options;
  std::string default_option;
  double timeout_s = 0;    // lab seconds until the default is taken
  nlohmann::json details;  // e.g. {"row": 2, "col": 7}
  std::string posted_at;   // ISO 8601 UTC
  std::string deadline;    // ISO 8601 UTC, wall clock (lab seconds divided by the time scale)
  std::optional<std::string> answer;
  std::string answered_by;  // "operator", "default", "simulator", or the API client's name

  nlohmann::json to_json() const;
};

// The request a script's lab.operator.request{...} table describes (no id, times or answer yet);
// Error{script_error} saying what is wrong with it.
OperatorRequest parse_operator_request(const nlohmann::json& spec);

// Something that can carry out an operator action itself. nullopt: it cannot, a person must.
class OperatorHands {
 public:
  virtual ~OperatorHands() = default;
  virtual boost::asio::awaitable<std::optional<nlohmann::json>> perform(const std::string& action,
                                                                        const nlohmann::json& details) = 0;
  // Whether perform would do `action` itself (a dry run lists the rest as waits for a person).
  virtual bool can_perform(const std::string& action) const = 0;
  // Undoes what `action` (done by perform with `details`) left out of the lab's rest, when the run that asked for it
  // ends in any state — finished, failed, aborted, paused or stopped with the daemon: a script's own last step
  // ("put the chart back") is not reached when it fails or is aborted mid-way, and the next run would photograph a
  // chart still posed for a lens calibration. A run that continues redoes the action first (LabState's
  // done_by_hands). What was done, or nullopt when the action left nothing to put back (the default).
  virtual boost::asio::awaitable<std::optional<nlohmann::json>> put_back(const std::string& action, const nlohmann::json& details) {
    (void)action;
    (void)details;
    co_return std::nullopt;
  }
};

class OperatorDesk {
 public:
  // "posted", "answered", "defaulted", "withdrawn": for the event log and live clients.
  using Listener = std::function<void(const std::string& event, const OperatorRequest&)>;
  void set_listener(Listener listener) { listener_ = std::move(listener); }

  const OperatorRequest& post(OperatorRequest request);
  // Throws Error{not_found} for an unknown or finished request, Error{bad_parameter} naming the
  // options for an answer that is not one of them.
  const OperatorRequest& answer(const std::string& id, const std::string& option, const std::string& who);
  // The default, at the deadline.
  void take_default(const std::string& id);
  // The execution stopped (pause, abort, shutdown) while the question was open: it is asked again
  // when the execution continues.
  void withdraw(const std::string& id, const std::string& why);
  // The request with its answer, once answered; removes it from the desk.
  std::optional<OperatorRequest> take_answered(const std::string& id);

  std::vector<OperatorRequest> pending() const;
  std::optional<OperatorRequest> find(const std::string& id) const;

 private:
  void notify(const std::string& event, const OperatorRequest& r) {
    if (listener_) listener_(event, r);
  }
  std::map<std::string, OperatorRequest> open_;
  Listener listener_;
};

}  // namespace colorlab::campaigns
