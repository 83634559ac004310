#pragma once
// Lua values and JSON, both ways. A table whose keys are exactly 1..n is an array; any other table
// is an object with string keys (numbers become their decimal text). Functions, userdata and
// cycles are refused with a message naming where they were found.
#include <string>

#include <nlohmann/json.hpp>

struct lua_State;

namespace colorlab::campaigns {

void push_json(lua_State* L, const nlohmann::json& value);
// Throws Error{script_error} for a value JSON cannot hold; `what` names it in the message.
nlohmann::json to_json(lua_State* L, int index, const std::string& what = "value");

}  // namespace colorlab::campaigns
