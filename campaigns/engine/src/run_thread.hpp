#pragma once
// A campaign script loaded into a sandbox with the lab API bound to `sink`, and its run function
// as the coroutine the caller resumes with the parameters (one argument already pushed). Shared by
// the engine and the dry run, so both run a script exactly the same way.
#include <functional>
#include <string>

#include <boost/asio/awaitable.hpp>

#include <nlohmann/json.hpp>

#include "colorlab/campaigns/lab_api.hpp"
#include "colorlab/campaigns/lua_sandbox.hpp"
#include "colorlab/campaigns/script.hpp"

namespace colorlab::campaigns {

// Throws Error{script_error} when the script does not return a campaign table with a run function.
// "name.lua:12: message" → 12 (0 if the message has no position).
int line_of(const std::string& message, const std::string& script_file);
// The line of the script that made the current (yielded) lab call.
int calling_line(lua_State* thread);

lua_State* start_run_thread(LuaSandbox& sandbox, const CampaignScript& script, const nlohmann::json& params, LabCallSink* sink);

// A long computation the script handed to its sink (lab.analysis.characterize's fit) for the run's
// `compute` (ScriptRunSetup::compute, DryRunSetup::compute: the daemon's worker pool) to carry out
// off the script's thread. Not a lab call: nothing is journaled, and a replay computes it again.
class HandedComputation {
 public:
  using Runner = std::function<boost::asio::awaitable<nlohmann::json>(std::string what, std::function<nlohmann::json()> job)>;

  // LabCallSink::compute: takes `job` when there is a runner to give it to; false leaves it to run inline.
  bool take(const Runner& runner, const std::string& what, std::function<nlohmann::json()>& job);
  bool pending() const { return pending_; }
  // Runs it through `runner` and pushes what the script resumes with onto `thread`: the result and
  // true, or the job's error message and false (lab_api's finish_computed raises it). Returns 2.
  boost::asio::awaitable<int> run(const Runner& runner, lua_State* thread);

 private:
  bool pending_ = false;
  std::string what_;
  std::function<nlohmann::json()> job_;
};

}  // namespace colorlab::campaigns
