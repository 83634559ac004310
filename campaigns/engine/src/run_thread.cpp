#include "run_thread.hpp"

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

}  // namespace colorlab::campaigns
