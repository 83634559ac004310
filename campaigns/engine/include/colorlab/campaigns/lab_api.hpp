#pragma once
// The `lab` table a campaign script sees: instruments in lab terms, plus record, progress, log,
// checkpoint and the analysis library. Calls that touch an instrument or take time yield the
// script's coroutine with a request the engine carries out (or answers from the journal on
// replay); the rest run at once. The yielding calls and their arguments are the registry's
// (lab_calls.hpp); arguments are checked here so an error names the script line.
#include <functional>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/campaigns/lab_calls.hpp"

struct lua_State;

namespace colorlab::campaigns {

// What the engine offers the Lua side. Implementations must not throw through Lua: the closures
// catch and turn exceptions into Lua errors.
class LabCallSink {
 public:
  virtual ~LabCallSink() = default;
  virtual bool is_campaign_thread(lua_State* L) const = 0;
  // A call the engine performs between two resumes of the script (it yields right after).
  virtual void request(std::string call, nlohmann::json args) = 0;
  virtual void record(const std::string& step, const nlohmann::json& fields) = 0;
  virtual void progress(double fraction, const std::string& label) = 0;
  virtual void log(const std::string& text) = 0;
  // A long computation (lab.analysis.characterize's fit): true when the sink takes `job` to run it
  // elsewhere and resumes the script with its result (the script yields meanwhile); false leaves
  // `job` to run at once, on the script's thread. The job owns what it reads.
  virtual bool compute(const std::string& /*what*/, std::function<nlohmann::json()>& /*job*/) { return false; }
};

// A sink's record(): throws Error{script_error} when the script recorded `step` before in this run
// (each lab.record needs its own step key), otherwise remembers it.
void claim_step(std::set<std::string>& recorded, const std::string& step);

// Sets the global `lab` in L. With sink == nullptr (reading a script's declaration) every call
// raises "only inside run()".
void install_lab_api(lua_State* L, LabCallSink* sink);

}  // namespace colorlab::campaigns
