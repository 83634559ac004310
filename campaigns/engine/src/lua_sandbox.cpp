#include "colorlab/campaigns/lua_sandbox.hpp"

#include <cstdlib>
#include <cstring>

#include <lua5.4/lua.hpp>

#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

namespace {

// Runs once in every new state, before the unsafe parts are removed. Written in Lua because it is
// shorter and reads as what a script sees.
constexpr const char* kPrelude = R"lua(
local next, type, tostring, error, sort, rawget = next, type, tostring, error, table.sort, rawget
local raw_load = load

-- Replay must see the same order in every process; Lua randomises string hashing per process.
local function key_order(a, b)
  local ta, tb = type(a), type(b)
  if ta ~= tb then return ta < tb end
  if ta == "number" or ta == "string" then return a < b end
  if ta == "boolean" then return (not a) and b end
  return tostring(a) < tostring(b)
end
function pairs(t)
  if type(t) ~= "table" then error("bad argument #1 to 'pairs' (table expected, got " .. type(t) .. ")", 2) end
  local keys, n = {}, 0
  for k in next, t do n = n + 1; keys[n] = k end
  sort(keys, key_order)
  local i = 0
  return function()
    i = i + 1
    local k = keys[i]
    if k ~= nil then return k, t[k] end
  end, t, nil
end

local sandbox_env = _G
function load(chunk, name, mode, env)
  if type(chunk) ~= "string" then error("load takes the script text as a string in a campaign script", 2) end
  if chunk:byte(1) == 27 then error("load of precompiled bytecode is forbidden in campaign scripts", 2) end
  return raw_load(chunk, name, "t", env or sandbox_env)
end

local function forbidden(lib)
  return setmetatable({}, {
    __index = function(_, k) error(lib .. "." .. tostring(k) .. " is forbidden in campaign scripts (no files, processes or network; use the lab API)", 2) end,
    __newindex = function() error(lib .. " is forbidden in campaign scripts", 2) end,
    __metatable = false,
  })
end
io, os, debug, package = forbidden("io"), forbidden("os"), forbidden("debug"), forbidden("package")
local function forbidden_function(name)
  return function() error(name .. " is forbidden in campaign scripts", 2) end
end
require = forbidden_function("require")
dofile = forbidden_function("dofile")
loadfile = forbidden_function("loadfile")
collectgarbage = forbidden_function("collectgarbage")
string.dump = forbidden_function("string.dump")
getmetatable("").__metatable = false
)lua";

}  // namespace

LuaSandbox& sandbox_of(lua_State* L) { return **static_cast<LuaSandbox**>(lua_getextraspace(L)); }

LuaSandbox::LuaSandbox(std::string script_name, ScriptLimits limits, std::uint64_t random_seed)
    : name_(std::move(script_name)), limits_(limits) {
  L_ = lua_newstate(&LuaSandbox::allocate, this);
  if (!L_) throw Error(ErrorClass::internal, "cannot create a Lua state for " + name_);
  *static_cast<LuaSandbox**>(lua_getextraspace(L_)) = this;
  const luaL_Reg libs[] = {
      {LUA_GNAME, luaopen_base},
      {LUA_TABLIBNAME, luaopen_table},
      {LUA_STRLIBNAME, luaopen_string},
      {LUA_MATHLIBNAME, luaopen_math},
      {LUA_UTF8LIBNAME, luaopen_utf8},
      {LUA_COLIBNAME, luaopen_coroutine},
  };
  for (const auto& lib : libs) {
    luaL_requiref(L_, lib.name, lib.func, 1);
    lua_pop(L_, 1);
  }
  if (luaL_loadbufferx(L_, kPrelude, std::strlen(kPrelude), "=sandbox", "t") != LUA_OK ||
      lua_pcall(L_, 0, 0, 0) != LUA_OK) {
    std::string msg = lua_tostring(L_, -1) ? lua_tostring(L_, -1) : "?";
    lua_close(L_);
    L_ = nullptr;
    throw Error(ErrorClass::internal, "the campaign sandbox failed to initialise: " + msg);
  }
  // A replayed script must draw the same random numbers as the first run did.
  lua_getglobal(L_, "math");
  lua_getfield(L_, -1, "randomseed");
  lua_pushinteger(L_, static_cast<lua_Integer>(random_seed & 0x7fffffffffffffffULL));
  lua_pushinteger(L_, 0);
  lua_call(L_, 2, 0);
  lua_pop(L_, 1);
  lua_sethook(L_, &LuaSandbox::count_hook, LUA_MASKCOUNT, static_cast<int>(limits_.slice));
}

LuaSandbox::~LuaSandbox() {
  if (L_) lua_close(L_);
}

void* LuaSandbox::allocate(void* ud, void* ptr, std::size_t old_size, std::size_t new_size) {
  auto* self = static_cast<LuaSandbox*>(ud);
  std::size_t old_bytes = ptr ? old_size : 0;
  if (new_size == 0) {
    std::free(ptr);
    self->memory_ -= old_bytes;
    return nullptr;
  }
  if (new_size > old_bytes && self->memory_ - old_bytes + new_size > self->limits_.memory_bytes) {
    if (self->kill_reason_.empty()) {
      self->kill_reason_ = "memory limit of " + std::to_string(self->limits_.memory_bytes >> 20) +
                           " MiB exceeded (a table growing without end?)";
    }
    return nullptr;  // Lua raises "not enough memory"; the hook then ends the script
  }
  void* p = std::realloc(ptr, new_size);
  if (p) self->memory_ = self->memory_ - old_bytes + new_size;
  return p;
}

void LuaSandbox::kill(lua_State* L, std::string reason) {
  if (kill_reason_.empty()) {
    lua_Debug ar;
    std::string where = name_;
    if (lua_getstack(L, 0, &ar) && lua_getinfo(L, "l", &ar) && ar.currentline > 0) {
      where += ":" + std::to_string(ar.currentline);
    }
    kill_reason_ = where + ": " + reason;
  }
}

void LuaSandbox::count_hook(lua_State* L, lua_Debug* /*ar*/) {
  LuaSandbox& self = sandbox_of(L);
  if (!self.killed()) {
    self.used_ += self.limits_.slice;
    if (self.used_ > self.limits_.instruction_budget) {
      self.kill(L, "instruction budget of " + std::to_string(self.limits_.instruction_budget) +
                       " exceeded without a lab call (an endless loop?)");
    }
  }
  if (self.killed()) {
    // From now on every instruction raises, so a script's pcall cannot keep it alive.
    lua_sethook(L, &LuaSandbox::count_hook, LUA_MASKCOUNT, 1);
    if (self.yielding_thread_ && self.yielding_thread_ != L) {
      lua_sethook(self.yielding_thread_, &LuaSandbox::count_hook, LUA_MASKCOUNT, 1);
    }
    lua_pushstring(L, self.kill_reason_.c_str());
    lua_error(L);
  }
  if (L == self.yielding_thread_ && lua_isyieldable(L)) {
    self.slice_yield_ = true;
    lua_yield(L, 0);
  }
}

void LuaSandbox::run_chunk(const std::string& source) {
  if (!source.empty() && source[0] == '\x1b') {
    throw Error(ErrorClass::script_error, name_ + ": precompiled bytecode is not accepted; give the script as text");
  }
  std::string chunk_name = "@" + name_;
  if (luaL_loadbufferx(L_, source.data(), source.size(), chunk_name.c_str(), "t") != LUA_OK) {
    std::string msg = lua_tostring(L_, -1) ? lua_tostring(L_, -1) : "syntax error";
    lua_pop(L_, 1);
    throw Error(ErrorClass::script_error, msg, "fix the script's syntax; `luac5.4 -p FILE` shows the same error");
  }
  if (lua_pcall(L_, 0, 1, 0) != LUA_OK) {
    std::string msg = lua_tostring(L_, -1) ? lua_tostring(L_, -1) : "error object is not a string";
    lua_pop(L_, 1);
    if (killed()) msg = kill_reason_;
    throw Error(ErrorClass::script_error, msg, "the script's top level failed before its run function started");
  }
}

}  // namespace colorlab::campaigns
