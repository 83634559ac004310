#pragma once
// A campaign script loaded into a sandbox with the lab API bound to `sink`, and its run function
// as the coroutine the caller resumes with the parameters (one argument already pushed). Shared by
// the engine and the dry run, so both run a script exactly the same way.
#include <string>

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

}  // namespace colorlab::campaigns
