#include "colorlab/campaigns/lab_api.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <vector>

#include <lua5.4/lua.hpp>

#include "colorlab/analysis/statistics.hpp"
#include "colorlab/analysis/uniformity.hpp"
#include "colorlab/campaigns/characterize.hpp"
#include "colorlab/campaigns/chart_plan.hpp"
#include "colorlab/campaigns/floor_photograph.hpp"
#include "colorlab/campaigns/lens_calibration.hpp"
#include "colorlab/campaigns/lua_value.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

namespace {

LabCallSink* sink_of(lua_State* L) { return static_cast<LabCallSink*>(lua_touserdata(L, lua_upvalueindex(1))); }

// Raises the message on top of the stack as a Lua error with the calling line in front. Only call
// it once every C++ object of the caller is destroyed: lua_error longjmps.
int raise_top(lua_State* L) {
  luaL_where(L, 1);
  lua_insert(L, -2);
  lua_concat(L, 2);
  return lua_error(L);
}

// Runs `f`, turning an exception into a Lua error at the caller's line. The message is pushed and
// every C++ object of the try block is destroyed before lua_error longjmps over this frame.
template <class F>
void guarded(lua_State* L, F&& f) {
  bool failed = false;
  {
    try {
      f();
    } catch (const Error& e) {
      lua_pushstring(L, e.info().message.c_str());
      failed = true;
    } catch (const std::exception& e) {
      lua_pushstring(L, e.what());
      failed = true;
    }
  }
  if (failed) raise_top(L);
}

int yielding_call(lua_State* L) {
  LabCallSink* sink = sink_of(L);
  const char* call = lua_tostring(L, lua_upvalueindex(2));
  if (!sink) return luaL_error(L, "lab.%s can only be called while the campaign runs (inside run)", call);
  if (!sink->is_campaign_thread(L) || !lua_isyieldable(L)) {
    return luaL_error(L, "lab.%s cannot be called from a coroutine or a callback (table.sort, string.gsub); call it from run", call);
  }
  guarded(L, [&] {
    json args = json::array();
    int n = lua_gettop(L);
    for (int i = 1; i <= n; ++i) args.push_back(to_json(L, i, "argument #" + std::to_string(i) + " to lab." + call));
    while (!args.empty() && args.back().is_null()) args.erase(args.end() - 1);
    std::string problem = check_lab_args(lab_call(call), args);
    if (!problem.empty()) throw Error(ErrorClass::script_error, problem);
    sink->request(call, std::move(args));
  });
  lua_settop(L, 0);
  return lua_yield(L, 0);
}

int lab_record(lua_State* L) {
  LabCallSink* sink = sink_of(L);
  if (!sink) return luaL_error(L, "lab.record can only be called while the campaign runs (inside run)");
  guarded(L, [&] {
    if (lua_type(L, 1) != LUA_TSTRING) throw Error(ErrorClass::script_error, "bad argument #1 to lab.record (step key string expected)");
    if (lua_type(L, 2) != LUA_TTABLE) {
      throw Error(ErrorClass::script_error, "bad argument #2 to lab.record (table {quantity=, value=, unit=, instrument=, data=} expected)");
    }
    std::string step = lua_tostring(L, 1);
    json fields = to_json(L, 2, "lab.record's fields");
    if (step.empty() || step.size() > 256) throw Error(ErrorClass::script_error, "lab.record: the step key must be 1 to 256 characters");
    if (!fields.is_object() || !fields.contains("quantity") || !fields["quantity"].is_string()) {
      throw Error(ErrorClass::script_error, "lab.record: fields.quantity (a string) is required");
    }
    if (fields.contains("value") && !fields["value"].is_number() && !fields["value"].is_null()) {
      throw Error(ErrorClass::script_error, "lab.record: fields.value must be a number (put other payloads in fields.data)");
    }
    sink->record(step, fields);
  });
  return 0;
}

int lab_progress(lua_State* L) {
  LabCallSink* sink = sink_of(L);
  if (!sink) return luaL_error(L, "lab.progress can only be called while the campaign runs (inside run)");
  double fraction = luaL_checknumber(L, 1);
  if (!(fraction >= 0 && fraction <= 1)) return luaL_error(L, "lab.progress takes a fraction from 0 to 1");
  std::size_t n = 0;
  const char* label = luaL_optlstring(L, 2, "", &n);
  guarded(L, [&] { sink->progress(fraction, std::string(label, n)); });
  return 0;
}

int lab_log(lua_State* L) {
  LabCallSink* sink = sink_of(L);
  int n = lua_gettop(L);
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  for (int i = 1; i <= n; ++i) {
    if (i > 1) luaL_addchar(&b, ' ');
    luaL_tolstring(L, i, nullptr);
    luaL_addvalue(&b);
  }
  luaL_pushresult(&b);
  if (sink) guarded(L, [&] { sink->log(lua_tostring(L, -1)); });
  return 0;
}

// lab.analysis.summarize({...}) → {count, mean, stdev, median, min, max}: the one summary used everywhere.
int analysis_summarize(lua_State* L) {
  guarded(L, [&] {
    if (lua_type(L, 1) != LUA_TTABLE) throw Error(ErrorClass::script_error, "lab.analysis.summarize takes a list of numbers");
    json list = to_json(L, 1, "lab.analysis.summarize's list");
    std::vector<double> values;
    for (std::size_t i = 0; i < (list.is_array() ? list.size() : 0); ++i) {
      if (!list[i].is_number()) {
        throw Error(ErrorClass::script_error, "lab.analysis.summarize: element " + std::to_string(i + 1) + " is not a number");
      }
      values.push_back(list[i].get<double>());
    }
    if (values.empty()) throw Error(ErrorClass::script_error, "lab.analysis.summarize: no values");
    analysis::Summary s = analysis::summarize(values);
    lua_settop(L, 0);
    push_json(L, json{{"count", s.count}, {"mean", s.mean}, {"stdev", s.stdev}, {"median", s.median}, {"min", s.min}, {"max", s.max}});
  });
  return 1;
}

Eigen::MatrixXd matrix_from(const json& rows, const char* what) {
  if (!rows.is_array() || rows.empty() || !rows[0].is_array() || rows[0].empty()) {
    throw Error(ErrorClass::script_error, std::string(what) + " must be a list of rows of numbers");
  }
  Eigen::MatrixXd m(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(rows[0].size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    if (!rows[r].is_array() || rows[r].size() != rows[0].size()) {
      throw Error(ErrorClass::script_error, std::string(what) + ": every row needs " + std::to_string(rows[0].size()) + " values");
    }
    for (std::size_t c = 0; c < rows[r].size(); ++c) {
      if (!rows[r][c].is_number()) throw Error(ErrorClass::script_error, std::string(what) + " holds a value that is not a number");
      m(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = rows[r][c].get<double>();
    }
  }
  return m;
}

json rows_of(const Eigen::MatrixXd& m) {
  json out = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    json row = json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    out.push_back(row);
  }
  return out;
}

// The optional {window_rows =, window_cols =} argument at `index` (the chart's size in grid spots).
analysis::UniformityOptions window_options(lua_State* L, int index, const char* what) {
  analysis::UniformityOptions o;
  json options = lua_gettop(L) >= index ? to_json(L, index, what) : json::object();
  if (options.is_object()) {
    o.window_rows = options.value("window_rows", o.window_rows);
    o.window_cols = options.value("window_cols", o.window_cols);
  }
  return o;
}

// lab.analysis.uniformity(left_half_grid, {window_rows = 4, window_cols = 5}) → §6.2 (Tables 3–6).
int analysis_uniformity(lua_State* L) {
  guarded(L, [&] {
    json grid = to_json(L, 1, "lab.analysis.uniformity's grid");
    auto o = window_options(L, 2, "lab.analysis.uniformity's options");
    auto u = analysis::analyse_uniformity(matrix_from(grid, "lab.analysis.uniformity's grid"), o);
    json result{{"min", u.min},
                {"max", u.max},
                {"best", {{"row", u.best.row}, {"col", u.best.col}, {"stdev", u.best.stdev}}},
                {"window_stdev", rows_of(u.window_stdev)},
                {"full", rows_of(u.full)},
                {"difference", rows_of(u.difference)}};
    lua_settop(L, 0);
    push_json(L, result);
  });
  return 1;
}

// lab.analysis.dimmer_proportionality(full_difference, low_difference, setting) → {max_abs_error, error, scaled}.
int analysis_dimmer(lua_State* L) {
  guarded(L, [&] {
    json full = to_json(L, 1, "full_difference");
    json low = to_json(L, 2, "low_difference");
    if (!lua_isnumber(L, 3)) throw Error(ErrorClass::script_error, "lab.analysis.dimmer_proportionality: setting (0..1) expected as argument #3");
    double setting = lua_tonumber(L, 3);
    auto d = analysis::dimmer_proportionality(matrix_from(full, "full_difference"), matrix_from(low, "low_difference"), setting);
    json result{{"setting", d.setting}, {"max_abs_error", d.max_abs_error}, {"error", rows_of(d.error)}, {"scaled", rows_of(d.scaled)}};
    lua_settop(L, 0);
    push_json(L, result);
  });
  return 1;
}

// lab.analysis.compare_lamps({names...}, {left_half_grid...}, {window_rows=, window_cols=}) → per lamp {name, min, max, range, best, worst_window}.
int analysis_compare_lamps(lua_State* L) {
  guarded(L, [&] {
    json names = to_json(L, 1, "lab.analysis.compare_lamps's names");
    json grids = to_json(L, 2, "lab.analysis.compare_lamps's grids");
    auto o = window_options(L, 3, "lab.analysis.compare_lamps's options");
    if (!names.is_array() || !grids.is_array() || names.size() != grids.size() || names.empty()) {
      throw Error(ErrorClass::script_error, "lab.analysis.compare_lamps takes a list of lamp names and a list of as many grids");
    }
    std::vector<std::string> n;
    std::vector<analysis::UniformityResult> results;
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (!names[i].is_string()) throw Error(ErrorClass::script_error, "lab.analysis.compare_lamps: names must be strings");
      n.push_back(names[i].get<std::string>());
      results.push_back(analysis::analyse_uniformity(matrix_from(grids[i], "lab.analysis.compare_lamps's grid"), o));
    }
    json out = json::array();
    for (const auto& l : analysis::compare_lamps(n, results)) {
      out.push_back({
          {"name", l.name},
          {"min", l.min},
          {"max", l.max},
          {"range", l.range},
          {"best", {{"row", l.best.row}, {"col", l.best.col}, {"stdev", l.best.stdev}}},
          {"worst_window", l.worst_window},
      });
    }
    lua_settop(L, 0);
    push_json(L, out);
  });
  return 1;
}

// The stack holds what the engine resumed the script with: the result and true, or a message and false.
int finish_computed(lua_State* L, int /*status*/, lua_KContext /*ctx*/) {
  const bool ok = lua_toboolean(L, -1);
  lua_pop(L, 1);
  if (!ok) return raise_top(L);
  return 1;
}

// A computation that may take seconds (a fit): its arguments are read here, on the script's thread,
// and the sink may run it elsewhere (the daemon's worker pool) while the script waits, yielded, so
// that the daemon serves meanwhile. Without such a sink (a script's declaration, a coroutine of the
// script's own, the dry run) it runs here, as any analysis. `prepare` returns the job, which must own
// everything it reads. Every C++ object is gone before a Lua error longjmps over this frame.
template <class Prepare>
int computed(lua_State* L, const char* what, Prepare&& prepare) {
  LabCallSink* sink = sink_of(L);
  bool failed = false;
  bool yielded = false;
  {
    try {
      std::function<json()> job = prepare();
      if (sink && sink->is_campaign_thread(L) && lua_isyieldable(L) && sink->compute(what, job)) {
        yielded = true;
      } else {
        json result = job();
        lua_settop(L, 0);
        push_json(L, result);
      }
    } catch (const Error& e) {
      lua_pushstring(L, e.info().message.c_str());
      failed = true;
    } catch (const std::exception& e) {
      lua_pushstring(L, e.what());
      failed = true;
    }
  }
  if (failed) return raise_top(L);
  if (yielded) {
    lua_settop(L, 0);
    return lua_yieldk(L, 0, 0, finish_computed);
  }
  return 1;
}

// lab.analysis.characterize(camera_values, reference, options) → chapter 7's approaches (characterize.hpp).
int analysis_characterize(lua_State* L) {
  return computed(L, "lab.analysis.characterize", [L]() -> std::function<json()> {
    json camera = to_json(L, 1, "lab.analysis.characterize's camera values");
    json reference = to_json(L, 2, "lab.analysis.characterize's reference");
    json options = lua_gettop(L) >= 3 && !lua_isnil(L, 3) ? to_json(L, 3, "lab.analysis.characterize's options") : json::object();
    return [camera = std::move(camera), reference = std::move(reference), options = std::move(options)] {
      return characterize(camera, reference, options);
    };
  });
}

// lab.analysis.floor_luminance(photograph, calibration, {degree =, subset =}) → the floor's luminance (floor_photograph.hpp).
int analysis_floor_luminance(lua_State* L) {
  return computed(L, "lab.analysis.floor_luminance", [L]() -> std::function<json()> {
    json photo = to_json(L, 1, "lab.analysis.floor_luminance's photograph");
    json calibration = to_json(L, 2, "lab.analysis.floor_luminance's calibration");
    json options = lua_gettop(L) >= 3 && !lua_isnil(L, 3) ? to_json(L, 3, "lab.analysis.floor_luminance's options") : json::object();
    return [photo = std::move(photo), calibration = std::move(calibration), options = std::move(options)] {
      return floor_luminance(photo, calibration, options);
    };
  });
}

// lab.analysis.calibrate_lens(photographs, {camera =, lens =, …}) → the lab's lens calibration (lens_calibration.hpp).
int analysis_calibrate_lens(lua_State* L) {
  return computed(L, "lab.analysis.calibrate_lens", [L]() -> std::function<json()> {
    json photographs = to_json(L, 1, "lab.analysis.calibrate_lens's photographs");
    json options = lua_gettop(L) >= 2 && !lua_isnil(L, 2) ? to_json(L, 2, "lab.analysis.calibrate_lens's options") : json::object();
    return [photographs = std::move(photographs), options = std::move(options)] { return calibrate_lens(photographs, options); };
  });
}

// lab.chart.plan{chart=, first_x_mm=, first_y_mm=, pitch_mm=} → the chart's patches on the table in visiting order.
int chart_plan_fn(lua_State* L) {
  guarded(L, [&] {
    json options = lua_gettop(L) >= 1 && !lua_isnil(L, 1) ? to_json(L, 1, "lab.chart.plan's options") : json::object();
    if (options.is_array() && options.empty()) options = json::object();
    json plan = chart_plan(options);
    lua_settop(L, 0);
    push_json(L, plan);
  });
  return 1;
}

void set_function(lua_State* L, const char* field, lua_CFunction f, LabCallSink* sink, const char* call = nullptr) {
  lua_pushlightuserdata(L, sink);
  if (call) {
    lua_pushstring(L, call);
    lua_pushcclosure(L, f, 2);
  } else {
    lua_pushcclosure(L, f, 1);
  }
  lua_setfield(L, -2, field);
}

}  // namespace

void claim_step(std::set<std::string>& recorded, const std::string& step) {
  if (!recorded.insert(step).second) {
    throw Error(ErrorClass::script_error, "step '" + step + "' is recorded twice; each lab.record needs its own step key");
  }
}

void install_lab_api(lua_State* L, LabCallSink* sink) {
  lua_newtable(L);  // lab
  std::map<std::string, std::vector<std::string>> groups;
  for (const auto& c : lab_calls()) {
    const std::string call(c.name);
    auto dot = call.find('.');
    if (dot == std::string::npos) {
      set_function(L, call.c_str(), yielding_call, sink, call.c_str());
    } else {
      groups[call.substr(0, dot)].push_back(call);
    }
  }
  for (const auto& [group, calls] : groups) {
    lua_newtable(L);
    for (const auto& call : calls) set_function(L, call.substr(call.find('.') + 1).c_str(), yielding_call, sink, call.c_str());
    lua_setfield(L, -2, group.c_str());
  }
  set_function(L, "record", lab_record, sink);
  set_function(L, "progress", lab_progress, sink);
  set_function(L, "log", lab_log, sink);
  lua_newtable(L);
  lua_pushcfunction(L, analysis_summarize);
  lua_setfield(L, -2, "summarize");
  lua_pushcfunction(L, analysis_uniformity);
  lua_setfield(L, -2, "uniformity");
  lua_pushcfunction(L, analysis_dimmer);
  lua_setfield(L, -2, "dimmer_proportionality");
  lua_pushcfunction(L, analysis_compare_lamps);
  lua_setfield(L, -2, "compare_lamps");
  set_function(L, "characterize", analysis_characterize, sink);  // the sink may compute them off this thread
  set_function(L, "floor_luminance", analysis_floor_luminance, sink);
  set_function(L, "calibrate_lens", analysis_calibrate_lens, sink);
  lua_setfield(L, -2, "analysis");
  lua_newtable(L);
  lua_pushcfunction(L, chart_plan_fn);
  lua_setfield(L, -2, "plan");
  lua_setfield(L, -2, "chart");
  lua_setglobal(L, "lab");
}

}  // namespace colorlab::campaigns
