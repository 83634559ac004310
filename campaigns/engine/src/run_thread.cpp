#include "run_thread.hpp"

#include <optional>

#include <lua5.4/lua.hpp>

#include "colorlab/campaigns/lua_value.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

int line_of(const std::string& message, const std::string& script) {
  std::string prefix = script + ":";
  if (message.rfind(prefix, 0) != 0) return 0;
  try {
    return std::stoi(message.substr(prefix.size()));
  } catch (const std::exception&) {
    return 0;
  }
}

int calling_line(lua_State* thread) {
  lua_Debug ar;
  for (int level = 0; lua_getstack(thread, level, &ar); ++level) {
    if (lua_getinfo(thread, "Sl", &ar) && ar.currentline > 0 && std::string(ar.what) != "C") return ar.currentline;
  }
  return 0;
}

lua_State* start_run_thread(LuaSandbox& sandbox, const CampaignScript& script, const nlohmann::json& params, LabCallSink* sink) {
  const std::string file = script.name + ".lua";
  lua_State* L = sandbox.state();
  install_lab_api(L, sink);
  sandbox.run_chunk(script.source);
  if (!lua_istable(L, -1)) throw Error(ErrorClass::script_error, file + ": the script must return its campaign table");
  lua_getfield(L, -1, "run");
  if (!lua_isfunction(L, -1)) throw Error(ErrorClass::script_error, file + ": the campaign table has no run function");
  lua_State* thread = lua_newthread(L);
  lua_rotate(L, -2, 1);  // keep the thread referenced below the function
  lua_xmove(L, thread, 1);
  push_json(thread, params);
  sandbox.set_yielding_thread(thread);
  return thread;
}

bool HandedComputation::take(const Runner& runner, const std::string& what, std::function<nlohmann::json()>& job) {
  if (!runner) return false;
  what_ = what;
  job_ = std::move(job);
  pending_ = true;
  return true;
}

boost::asio::awaitable<int> HandedComputation::run(const Runner& runner, lua_State* thread) {
  pending_ = false;
  auto job = std::move(job_);
  std::optional<std::string> failure;
  nlohmann::json computed;
  try {
    // The awaitable first, then co_await it: no temporaries in the co_await expression (GCC 12).
    auto awaiting = runner(what_, std::move(job));
    computed = co_await std::move(awaiting);
  } catch (const Error& e) {
    failure = e.info().message;
  } catch (const std::exception& e) {
    failure = e.what();
  }
  if (failure) {
    lua_pushstring(thread, failure->c_str());
  } else {
    push_json(thread, computed);
  }
  lua_pushboolean(thread, failure ? 0 : 1);
  co_return 2;
}

}  // namespace colorlab::campaigns
