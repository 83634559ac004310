#include "colorlab/campaigns/lua_value.hpp"

#include <cmath>
#include <string_view>
#include <vector>

#include <lua5.4/lua.hpp>

#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

void push_json(lua_State* L, const json& value) {
  luaL_checkstack(L, 4, "JSON too deeply nested");
  switch (value.type()) {
    case json::value_t::null:
    case json::value_t::discarded: lua_pushnil(L); break;
    case json::value_t::boolean: lua_pushboolean(L, value.get<bool>()); break;
    case json::value_t::number_integer: lua_pushinteger(L, value.get<std::int64_t>()); break;
    case json::value_t::number_unsigned: lua_pushinteger(L, static_cast<lua_Integer>(value.get<std::uint64_t>())); break;
    case json::value_t::number_float: lua_pushnumber(L, value.get<double>()); break;
    case json::value_t::string: {
      const auto& s = value.get_ref<const std::string&>();
      lua_pushlstring(L, s.data(), s.size());
      break;
    }
    case json::value_t::binary: lua_pushnil(L); break;
    case json::value_t::array: {
      lua_createtable(L, static_cast<int>(value.size()), 0);
      lua_Integer i = 1;
      for (const auto& v : value) {
        push_json(L, v);
        lua_rawseti(L, -2, i++);
      }
      break;
    }
    case json::value_t::object: {
      lua_createtable(L, 0, static_cast<int>(value.size()));
      for (const auto& [k, v] : value.items()) {
        push_json(L, v);
        lua_setfield(L, -2, k.c_str());
      }
      break;
    }
  }
}

namespace {

// Well-formed UTF-8 (Unicode 15, table 3-7): no overlong forms, surrogates or code points past U+10FFFF.
bool valid_utf8(std::string_view s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    std::size_t len = 0;
    unsigned char lo = 0x80, hi = 0xBF;
    if (b < 0x80) {
      ++i;
      continue;
    } else if (b >= 0xC2 && b <= 0xDF) {
      len = 2;
    } else if (b >= 0xE0 && b <= 0xEF) {
      len = 3;
      if (b == 0xE0) lo = 0xA0;
      if (b == 0xED) hi = 0x9F;
    } else if (b >= 0xF0 && b <= 0xF4) {
      len = 4;
      if (b == 0xF0) lo = 0x90;
      if (b == 0xF4) hi = 0x8F;
    } else {
      return false;
    }
    if (i + len > s.size()) return false;
    for (std::size_t k = 1; k < len; ++k) {
      const auto c = static_cast<unsigned char>(s[i + k]);
      if (c < (k == 1 ? lo : 0x80) || c > (k == 1 ? hi : 0xBF)) return false;
    }
    i += len;
  }
  return true;
}

// Lua strings are bytes; JSON (the store, the API) holds UTF-8 text, and cannot even write anything else.
std::string text_of(lua_State* L, int index, const std::string& where) {
  std::size_t n = 0;
  const char* s = lua_tolstring(L, index, &n);
  if (!valid_utf8({s, n})) {
    throw Error(ErrorClass::script_error, where + " is not UTF-8 text", "save the script as UTF-8");
  }
  return std::string(s, n);
}

json convert(lua_State* L, int index, const std::string& where, int depth) {
  index = lua_absindex(L, index);
  if (depth > 64) throw Error(ErrorClass::script_error, where + " is nested too deeply (a cycle?)");
  switch (lua_type(L, index)) {
    case LUA_TNIL: return nullptr;
    case LUA_TBOOLEAN: return lua_toboolean(L, index) != 0;
    case LUA_TNUMBER:
      if (lua_isinteger(L, index)) return static_cast<std::int64_t>(lua_tointeger(L, index));
      {
        double d = lua_tonumber(L, index);
        // JSON has no NaN or infinity; null says "no value" the same way the store does.
        if (!std::isfinite(d)) return nullptr;
        return d;
      }
    case LUA_TSTRING: return text_of(L, index, where);
    case LUA_TTABLE: {
      luaL_checkstack(L, 4, "table too deeply nested");
      lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L, index));
      std::size_t count = 0;
      bool keys_are_sequence = true;
      lua_pushnil(L);
      while (lua_next(L, index) != 0) {
        ++count;
        if (!lua_isinteger(L, -2) || lua_tointeger(L, -2) < 1 || lua_tointeger(L, -2) > n) keys_are_sequence = false;
        lua_pop(L, 1);
      }
      if (count == 0) return json::object();
      if (keys_are_sequence && static_cast<lua_Integer>(count) == n) {
        json arr = json::array();
        for (lua_Integer i = 1; i <= n; ++i) {
          lua_rawgeti(L, index, i);
          arr.push_back(convert(L, -1, where + "[" + std::to_string(i) + "]", depth + 1));
          lua_pop(L, 1);
        }
        return arr;
      }
      // Object: keys sorted by json's std::map, so the text is the same in every process.
      json obj = json::object();
      lua_pushnil(L);
      while (lua_next(L, index) != 0) {
        std::string key;
        if (lua_type(L, -2) == LUA_TSTRING) {
          key = text_of(L, -2, where + "'s key");
        } else if (lua_type(L, -2) == LUA_TNUMBER) {
          lua_pushvalue(L, -2);
          key = lua_tostring(L, -1);
          lua_pop(L, 1);
        } else {
          std::string type = luaL_typename(L, -2);
          lua_pop(L, 2);
          throw Error(ErrorClass::script_error, where + " has a key of type " + type + "; use strings or numbers");
        }
        obj[key] = convert(L, -1, where + "." + key, depth + 1);
        lua_pop(L, 1);
      }
      return obj;
    }
    default:
      throw Error(ErrorClass::script_error,
                  where + " is a " + std::string(luaL_typename(L, index)) + ", which cannot be stored or passed to the lab");
  }
}

}  // namespace

json to_json(lua_State* L, int index, const std::string& what) { return convert(L, index, what, 0); }

}  // namespace colorlab::campaigns
