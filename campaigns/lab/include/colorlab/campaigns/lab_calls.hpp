#pragma once
// The lab's calls, in one registry: per call its name (`lab.<name>` in a script), its arguments, how
// the journal and a replay treat it, the instrument role it needs, the live lab's handler and the dry
// run's answer, what it does to the lab's state (LabState, rebuilt on replay), and how its time is
// counted (the engine learns it, the dry run estimates it: call_timing.hpp). Lab::perform dispatches
// through it, DryLab answers through it, the sandbox builds the script's `lab` table from it, and
// docs/campaigns.md's tables of calls are checked against it (tests/campaigns/lab_calls_test.cpp).
// A new call is one row (lab_calls.cpp) and its two handlers.
#include <string>
#include <string_view>
#include <vector>

#include <boost/asio/awaitable.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/control.hpp"

namespace colorlab::campaigns {

class Lab;
class DryLab;
struct DryProblem;
struct LabState;

// How the journal and a replay treat a call: an effect changes the lab (a replay folds it into the
// state the lab is restored to), a reading returns a value (a replay answers it from the journal),
// control only marks a safe point (the step is committed; nothing is journaled).
enum class CallKind {
  effect,
  reading,
  control
};

// An argument's type as a script passes it; a list and a table both accept an empty Lua table.
enum class ArgType {
  string,
  number,
  boolean,
  list,
  table
};
struct ArgSpec {
  ArgType type;
  bool optional = false;
};

// What the dry run's answer is told besides the arguments.
struct DryContext {
  double lab_now_s = 0;               // lab seconds since the dry run began
  std::vector<DryProblem>& problems;  // limits the call breaks: noted, and the call answered anyway
};

// What a call does to the lamps' warm-up, which decides how long the next wait_stable takes.
enum class LampEffect {
  none,
  relight,  // the lamps lit after the call are those it names; one that stays lit stays warm
  settle,   // waits until the lit lamps are stable: they are warm from now on
};

// How a call's time is counted. No source publishes how long a Spectrolino reading, a table move or a
// lamp's warm-up takes, so the engine times every live call under a key and the dry run adds up the
// same keys; a key this lab has never timed falls back to `nominal_s`, stated and flagged as assumed.
struct CallTimingRule {
  // Assumed lab seconds per unit, on the long side (an estimate that is too short ruins a night, one
  // too long only starts it earlier). Argyll's timeouts bound the Spectrolino's (measure ≤ 12 s,
  // move ≤ 10 s); the rest are a few exchanges on a serial line.
  double nominal_s = 0;
  // The key's words after the call's name, when the time depends on an argument ("operator.request
  // place_chart"); nullptr: the name alone.
  std::string (*key_detail)(const nlohmann::json& args) = nullptr;
  // How many units the call counts for (frames × formats for a photograph), at least 1; nullptr: 1.
  double (*units)(const nlohmann::json& args) = nullptr;
  // Lab seconds the script asked for outright (lab.wait, a dimmer's settle_s): added exactly, never
  // learned; nullptr: none.
  double (*asked_wait_s)(const nlohmann::json& args) = nullptr;
  LampEffect lamps = LampEffect::none;
};

struct LabCall {
  using Perform = boost::asio::awaitable<nlohmann::json> (Lab::*)(const nlohmann::json& args,
                                                                  const ExecutionControl& control);
  using DryAnswer = nlohmann::json (DryLab::*)(const nlohmann::json& args, DryContext& context);

  std::string_view name;  // "meter.measure"
  CallKind kind;
  std::vector<ArgSpec> args;
  std::string_view role;  // the instrument role it needs ("luminance_meter", …); empty for none
  // What the arguments must satisfy beyond their types: empty when fine, else the problem in the
  // script author's terms. nullptr: nothing more.
  std::string (*check)(const nlohmann::json& args) = nullptr;
  // The live lab's handler; nullptr for control calls, which the engine handles itself.
  Perform perform = nullptr;
  // The dry run's answer; nullptr: the call answers null.
  DryAnswer dry_answer = nullptr;
  // What the completed call (live or replayed) changes in the state a resume restores; nullptr: nothing.
  void (*state_effect)(LabState& state, const nlohmann::json& args, const nlohmann::json& result) = nullptr;
  CallTimingRule timing{};
};

// Every call, by name.
const std::vector<LabCall>& lab_calls();
// The call named `name`, or nullptr.
const LabCall* find_lab_call(std::string_view name);
// The call named `name`; Error{internal} for a name no row has.
const LabCall& lab_call(std::string_view name);
CallKind kind_of(const std::string& call);
// Empty when `args` (trailing nils dropped) fit the call; otherwise what is wrong, in the script
// author's terms ("bad argument #2 to lab.table.move (number expected, got string)").
std::string check_lab_args(const LabCall& call, const nlohmann::json& args);

}  // namespace colorlab::campaigns
