// Issue 24: the lab's calls are one registry (lab_calls.hpp). The script's `lab` table is built from
// it, every call has what the live lab and the dry run need, and docs/campaigns.md's tables of calls
// list exactly its calls, so the docs cannot drift from the code.
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <lua5.4/lua.hpp>

#include "colorlab/campaigns/lab_api.hpp"
#include "colorlab/campaigns/lab_calls.hpp"

using colorlab::campaigns::CallKind;
using colorlab::campaigns::lab_calls;

namespace {

std::set<std::string> registry_names() {
  std::set<std::string> names;
  for (const auto& c : lab_calls()) names.insert(std::string(c.name));
  return names;
}

// The calls the rows of docs/campaigns.md's tables name in their first cell: `lab.group.call(...)`,
// and the shorthand `.call()` for another call of the same group in the same cell.
std::set<std::string> documented_calls() {
  const auto path = std::filesystem::path(COLORLAB_SOURCE_DIR) / "docs" / "campaigns.md";
  std::ifstream in(path);
  EXPECT_TRUE(in) << "cannot read " << path;
  std::set<std::string> names;
  const std::regex span("`([^`]*)`");
  const std::regex full(R"(^lab\.([a-z_]+)(\.[a-z_]+)?)");
  const std::regex shorthand(R"(^\.([a-z_]+)\()");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("| `lab.", 0) != 0) continue;
    const std::string first_cell = line.substr(1, line.find(" | ", 1) - 1);
    std::string group;
    for (std::sregex_iterator it(first_cell.begin(), first_cell.end(), span), end; it != end; ++it) {
      const std::string code = (*it)[1];
      std::smatch m;
      if (std::regex_search(code, m, full)) {
        group = m[2].matched ? m[1].str() : "";
        names.insert(m[1].str() + m[2].str());
      } else if (std::regex_search(code, m, shorthand) && !group.empty()) {
        names.insert(group + "." + m[1].str());
      }
    }
  }
  return names;
}

}  // namespace

TEST(LabCalls, TheDocsListExactlyTheRegistrysCalls) {
  const auto documented = documented_calls();
  ASSERT_GE(documented.size(), 20u) << "the parser found too few rows in docs/campaigns.md: it needs a look";
  EXPECT_EQ(documented, registry_names()) << "docs/campaigns.md's tables of lab calls and lab_calls.cpp disagree";
}

TEST(LabCalls, EveryCallHasItsLiveHandlerAndItsArgumentsReadLeftToRight) {
  std::set<std::string> seen;
  for (const auto& c : lab_calls()) {
    EXPECT_TRUE(seen.insert(std::string(c.name)).second) << c.name << " is in the registry twice";
    // Control calls are the engine's own (a checkpoint); every other call is the lab's to perform.
    EXPECT_EQ(c.perform == nullptr, c.kind == CallKind::control) << c.name;
    bool optional_seen = false;
    for (const auto& a : c.args) {
      EXPECT_FALSE(optional_seen && !a.optional) << c.name << ": a required argument after an optional one";
      optional_seen = optional_seen || a.optional;
    }
  }
}

TEST(LabCalls, TheScriptsLabTableIsTheRegistry) {
  lua_State* L = luaL_newstate();
  colorlab::campaigns::install_lab_api(L, nullptr);
  std::set<std::string> in_lua;
  // Yielding calls are lab.<name> or lab.<group>.<name>; record, progress, log, analysis.* and chart.*
  // run at once and are not lab calls.
  const std::set<std::string> immediate{"record", "progress", "log", "analysis", "chart"};
  lua_getglobal(L, "lab");
  lua_pushnil(L);
  while (lua_next(L, -2) != 0) {
    const std::string key = lua_tostring(L, -2);
    if (!immediate.count(key)) {
      if (lua_type(L, -1) == LUA_TFUNCTION) {
        in_lua.insert(key);
      } else if (lua_type(L, -1) == LUA_TTABLE) {
        lua_pushnil(L);
        while (lua_next(L, -2) != 0) {
          if (lua_type(L, -1) == LUA_TFUNCTION) in_lua.insert(key + "." + lua_tostring(L, -2));
          lua_pop(L, 1);
        }
      }
    }
    lua_pop(L, 1);
  }
  lua_close(L);
  EXPECT_EQ(in_lua, registry_names());
}
