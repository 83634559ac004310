#pragma once
// The lab's calls, in one registry: per call its name (`lab.<name>` in a script), its arguments, how
// the journal and a replay treat it, the instrument role it needs, the live lab's handler and the dry
// run's answer. Lab::perform dispatches through it, DryLab answers through it, the sandbox builds the
// script's `lab` table from it, and docs/campaigns.md's tables of calls are checked against it
// (tests/campaigns/lab_calls_test.cpp). A new call is one row (lab_calls.cpp) and its two handlers.
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

// How the journal and a replay treat a call: an effect changes the lab (a replay folds it into the
// state the lab is restored to), a reading returns a value (a replay answers it from the journal),
// control only marks a safe point (the step is committed; nothing is journaled).
enum class CallKind { effect, reading, control };

// An argument's type as a script passes it; a list and a table both accept an empty Lua table.
enum class ArgType { string, number, boolean, list, table };
struct ArgSpec {
  ArgType type;
  bool optional = false;
};

// What the dry run's answer is told besides the arguments.
struct DryContext {
  double lab_now_s = 0;               // lab seconds since the dry run began
  std::vector<DryProblem>& problems;  // limits the call breaks: noted, and the call answered anyway
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
