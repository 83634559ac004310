#include "colorlab/campaigns/lab_calls.hpp"

#include <algorithm>

#include "colorlab/campaigns/dry_lab.hpp"
#include "colorlab/campaigns/lab.hpp"
#include "colorlab/campaigns/lab_state.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

namespace {

constexpr ArgSpec string{ArgType::string};
constexpr ArgSpec number{ArgType::number};
constexpr ArgSpec boolean{ArgType::boolean};
constexpr ArgSpec list{ArgType::list};
constexpr ArgSpec table{ArgType::table};
constexpr ArgSpec optional_table{ArgType::table, true};

std::string dimmer_level(const json& args) {
  if (args[0].get<double>() >= 0 && args[0].get<double>() <= 100) return {};
  return "lab.dimmer.set takes a level in percent from 0 to 100, got " + args[0].dump();
}

std::string wait_seconds(const json& args) {
  if (args[0].get<double>() >= 0 && args[0].get<double>() <= 86400) return {};
  return "lab.wait takes seconds from 0 to 86400, got " + args[0].dump();
}

const json& options_arg(const json& args, std::size_t index) {
  static const json none = json::object();
  return args.is_array() && args.size() > index && args[index].is_object() ? args[index] : none;
}

double option_count(const json& args, const char* name, double fallback) {
  const json& o = options_arg(args, 0);
  return o.contains(name) && o[name].is_number() ? std::max(1.0, o[name].get<double>()) : fallback;
}

// Timing: a photograph costs per frame (and per format for the chart's), at the calls' own defaults.
std::string per_frame(const json&) { return "per frame"; }
std::string per_frame_and_format(const json&) { return "per frame and format"; }
double frames_captured(const json& args) { return option_count(args, "frames", 1.0); }
double floor_frames(const json& args) { return option_count(args, "frames", 8.0); }
double chart_frames_and_formats(const json& args) {
  const json& o = options_arg(args, 0);
  const double formats = o.contains("formats") && o["formats"].is_array() && !o["formats"].empty()
                             ? static_cast<double>(o["formats"].size())
                             : 4.0;  // raw, tiff16, tiff8, jpeg
  return option_count(args, "frames", 25.0) * formats;
}
// An operator's request costs what that action costs (placing a chart is not pressing a key).
std::string operator_action(const json& args) {
  const json& spec = options_arg(args, 0);
  return spec.contains("action") && spec["action"].is_string() ? spec["action"].get<std::string>() : "?";
}
double waited_outright(const json& args) {
  return args.is_array() && !args.empty() && args[0].is_number() ? args[0].get<double>() : 0.0;
}
double dimmer_settle(const json& args) {
  const json& o = options_arg(args, 1);
  return o.contains("settle_s") && o["settle_s"].is_number() ? std::max(0.0, o["settle_s"].get<double>()) : 0.0;
}

const char* word(ArgType t) {
  switch (t) {
    case ArgType::string: return "string";
    case ArgType::number: return "number";
    case ArgType::boolean: return "boolean";
    case ArgType::list: return "list";
    case ArgType::table: return "table";
  }
  return "?";
}

std::string json_kind(const json& v) {
  if (v.is_null()) return "nil";
  if (v.is_string()) return "string";
  if (v.is_number()) return "number";
  if (v.is_boolean()) return "boolean";
  if (v.is_array()) return "list";
  return "table";
}

std::vector<LabCall> by_name(std::vector<LabCall> calls) {
  std::sort(calls.begin(), calls.end(), [](const LabCall& a, const LabCall& b) { return a.name < b.name; });
  return calls;
}

}  // namespace

// Friend of Lab and DryLab: the rows name their private handlers.
const std::vector<LabCall>& lab_calls() {
  using K = CallKind;
  // Kept as laid out by hand: one row per call.
  // clang-format off
  static const std::vector<LabCall> calls = by_name({
      {"camera.capture", K::reading, {optional_table}, "camera", nullptr, &Lab::call_camera_capture, &DryLab::call_camera_capture,
       nullptr, {.nominal_s = 1.5, .key_detail = per_frame, .units = frames_captured}},
      {"camera.configure", K::effect, {table}, "camera", nullptr, &Lab::call_camera_configure, nullptr,
       &lab_state_effects::camera_configure, {.nominal_s = 0.5}},
      {"camera.photograph_chart", K::reading, {optional_table}, "camera", nullptr, &Lab::call_camera_photograph_chart,
       &DryLab::call_camera_photograph_chart, nullptr,
       {.nominal_s = 1.5, .key_detail = per_frame_and_format, .units = chart_frames_and_formats}},
      {"camera.photograph_floor", K::reading, {table}, "camera", nullptr, &Lab::call_camera_photograph_floor,
       &DryLab::call_camera_photograph_floor, nullptr,
       {.nominal_s = 1.5, .key_detail = per_frame, .units = floor_frames}},
      {"checkpoint", K::control, {}, "", nullptr, nullptr, nullptr, nullptr, {}},
      {"dimmer.set", K::effect, {number, optional_table}, "dimmer", dimmer_level, &Lab::call_dimmer_set, &DryLab::call_dimmer_set,
       &lab_state_effects::dimmer_set, {.nominal_s = 0.5, .asked_wait_s = dimmer_settle}},
      {"lamps.names", K::reading, {}, "lamps", nullptr, &Lab::call_lamps_names, &DryLab::call_lamps_names, nullptr, {.nominal_s = 0.2}},
      {"lamps.off", K::effect, {}, "lamps", nullptr, &Lab::call_lamps_off, &DryLab::call_lamps_off, &lab_state_effects::lamps_off,
       {.nominal_s = 0.2, .lamps = LampEffect::relight}},
      {"lamps.select", K::effect, {string}, "lamps", nullptr, &Lab::call_lamps_select, &DryLab::call_lamps_select,
       &lab_state_effects::lamps_select, {.nominal_s = 0.2, .lamps = LampEffect::relight}},
      {"lamps.set", K::effect, {list}, "lamps", nullptr, &Lab::call_lamps_set, &DryLab::call_lamps_set, &lab_state_effects::lamps_set,
       {.nominal_s = 0.2, .lamps = LampEffect::relight}},
      {"meter.measure", K::reading, {}, "luminance_meter", nullptr, &Lab::call_meter_measure, &DryLab::call_meter_measure, nullptr,
       {.nominal_s = 1.0}},
      {"now", K::reading, {}, "", nullptr, &Lab::call_now, &DryLab::call_now, nullptr, {}},
      {"operator.request", K::reading, {table}, "", nullptr, &Lab::call_operator_request, &DryLab::call_operator_request,
       &lab_state_effects::operator_request, {.nominal_s = 1.0, .key_detail = operator_action}},
      {"runs.chart_reference", K::reading, {string}, "", nullptr, &Lab::call_runs_chart_reference, &DryLab::call_runs_chart_reference, nullptr, {}},
      {"spectro.calibrate", K::effect, {}, "spectrophotometer", nullptr, &Lab::call_spectro_calibrate, nullptr,
       &lab_state_effects::spectro_calibrate, {.nominal_s = 6.0}},
      {"spectro.measure", K::reading, {}, "spectrophotometer", nullptr, &Lab::call_spectro_measure, &DryLab::call_spectro_measure,
       nullptr, {.nominal_s = 3.0}},
      {"spectro.mode", K::effect, {string}, "spectrophotometer", nullptr, &Lab::call_spectro_mode, &DryLab::call_spectro_mode,
       &lab_state_effects::spectro_mode, {.nominal_s = 0.2}},
      {"table.head_down", K::effect, {}, "table", nullptr, &Lab::call_table_head_down, nullptr, &lab_state_effects::table_head_down, {.nominal_s = 0.5}},
      {"table.head_up", K::effect, {}, "table", nullptr, &Lab::call_table_head_up, nullptr, &lab_state_effects::table_head_up, {.nominal_s = 0.5}},
      {"table.hold_paper", K::effect, {boolean}, "table", nullptr, &Lab::call_table_hold_paper, nullptr, &lab_state_effects::table_hold_paper,
       {.nominal_s = 0.5}},
      {"table.home", K::effect, {}, "table", nullptr, &Lab::call_table_home, nullptr, &lab_state_effects::table_home, {.nominal_s = 3.0}},
      {"table.measure_at", K::reading, {number, number}, "table", nullptr, &Lab::call_table_measure_at, &DryLab::call_table_measure_at,
       &lab_state_effects::table_measured_at, {.nominal_s = 3.0}},
      {"table.move", K::effect, {number, number}, "table", nullptr, &Lab::call_table_move, &DryLab::call_table_move,
       &lab_state_effects::table_move, {.nominal_s = 3.0}},
      {"table.read_patch", K::reading, {number, number, optional_table}, "table", nullptr, &Lab::call_table_read_patch,
       &DryLab::call_table_read_patch, &lab_state_effects::table_measured_at, {.nominal_s = 3.0}},
      {"wait", K::effect, {number}, "", wait_seconds, &Lab::call_wait, nullptr, nullptr, {.asked_wait_s = waited_outright}},
      {"wait_stable", K::reading, {optional_table}, "luminance_meter", nullptr, &Lab::call_wait_stable, &DryLab::call_wait_stable,
       nullptr, {.lamps = LampEffect::settle}},
  });
  // clang-format on
  return calls;
}

const LabCall* find_lab_call(std::string_view name) {
  const auto& calls = lab_calls();
  auto it = std::lower_bound(calls.begin(), calls.end(), name, [](const LabCall& c, std::string_view n) { return c.name < n; });
  return it != calls.end() && it->name == name ? &*it : nullptr;
}

const LabCall& lab_call(std::string_view name) {
  if (const LabCall* c = find_lab_call(name)) return *c;
  throw Error(ErrorClass::internal, "the lab has no call " + std::string(name));
}

CallKind kind_of(const std::string& call) {
  const LabCall* c = find_lab_call(call);
  if (!c) throw Error(ErrorClass::internal, "unknown lab call " + call);
  return c->kind;
}

std::string check_lab_args(const LabCall& call, const json& args) {
  const std::string name(call.name);
  const auto& spec = call.args;
  if (args.size() > spec.size()) {
    return "lab." + name + " takes " + std::to_string(spec.size()) + " argument(s), got " + std::to_string(args.size());
  }
  for (std::size_t i = 0; i < spec.size(); ++i) {
    const std::string want = word(spec[i].type);
    const json v = i < args.size() ? args[i] : json(nullptr);
    const std::string got = json_kind(v);
    if (got == "nil" && spec[i].optional) continue;
    bool ok = got == want || (want == "list" && got == "table" && v.empty()) || (want == "table" && got == "list" && v.empty());
    if (!ok) return "bad argument #" + std::to_string(i + 1) + " to lab." + name + " (" + want + " expected, got " + got + ")";
  }
  return call.check ? call.check(args) : std::string();
}

}  // namespace colorlab::campaigns
