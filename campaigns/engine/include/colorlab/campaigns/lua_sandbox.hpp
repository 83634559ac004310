#pragma once
// A Lua 5.4 state a campaign script cannot escape: only the base, table, string, math, utf8 and
// coroutine libraries; no io, os, package, debug, dofile, loadfile, string.dump or bytecode; a
// memory cap enforced by the allocator; an instruction budget enforced by a count hook, which also
// yields every `slice` instructions so a long computation never starves the daemon's event loop.
// Deterministic for replay: `pairs` visits keys in sorted order and math.random is seeded by us.
#include <cstdint>
#include <string>

struct lua_State;
struct lua_Debug;

namespace colorlab::campaigns {

struct ScriptLimits {
  std::size_t memory_bytes = 64u << 20;
  // Lua instructions a script may execute between two lab calls: an endless loop ends in about a
  // second instead of running all night.
  std::uint64_t instruction_budget = 200'000'000;
  std::uint64_t slice = 1'000'000;  // instructions between yields to the event loop
};

class LuaSandbox {
 public:
  LuaSandbox(std::string script_name, ScriptLimits limits, std::uint64_t random_seed);
  ~LuaSandbox();
  LuaSandbox(const LuaSandbox&) = delete;
  LuaSandbox& operator=(const LuaSandbox&) = delete;

  lua_State* state() const { return L_; }

  // Compiles `source` as text (never bytecode) under the chunk name "@<script_name>" and runs it;
  // leaves its first return value on the stack. Throws Error{script_error} naming script and line.
  void run_chunk(const std::string& source);

  // The thread whose count-hook ticks may yield (the campaign's coroutine); others only count.
  void set_yielding_thread(lua_State* thread) { yielding_thread_ = thread; }
  // A lab call happened: the budget counts afresh.
  void reset_budget() { used_ = 0; }
  // The script exceeded a limit: every further instruction raises, so `pcall` cannot swallow it.
  bool killed() const { return !kill_reason_.empty(); }
  const std::string& kill_reason() const { return kill_reason_; }
  // True if the last resume yielded because of the time slice (not a lab call).
  bool take_slice_yield() {
    bool y = slice_yield_;
    slice_yield_ = false;
    return y;
  }

 private:
  static void* allocate(void* ud, void* ptr, std::size_t old_size, std::size_t new_size);
  static void count_hook(lua_State* L, lua_Debug* ar);
  void kill(lua_State* L, std::string reason);

  std::string name_;
  ScriptLimits limits_;
  lua_State* L_ = nullptr;
  lua_State* yielding_thread_ = nullptr;
  std::size_t memory_ = 0;
  std::uint64_t used_ = 0;
  std::string kill_reason_;
  bool slice_yield_ = false;
};

// The sandbox that owns this state (stored in the state's extra space).
LuaSandbox& sandbox_of(lua_State* L);

}  // namespace colorlab::campaigns
