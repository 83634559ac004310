#include "colorlab/campaigns/lab_calls.hpp"

#include <algorithm>

#include "colorlab/campaigns/dry_lab.hpp"
#include "colorlab/campaigns/lab.hpp"
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
  static const std::vector<LabCall> calls = by_name({
      {"camera.capture", K::reading, {optional_table}, "camera", nullptr, &Lab::call_camera_capture, &DryLab::call_camera_capture},
      {"camera.configure", K::effect, {table}, "camera", nullptr, &Lab::call_camera_configure, nullptr},
      {"camera.photograph_chart", K::reading, {optional_table}, "camera", nullptr, &Lab::call_camera_photograph_chart,
       &DryLab::call_camera_photograph_chart},
      {"camera.photograph_floor", K::reading, {table}, "camera", nullptr, &Lab::call_camera_photograph_floor,
       &DryLab::call_camera_photograph_floor},
      {"checkpoint", K::control, {}, "", nullptr, nullptr, nullptr},
      {"dimmer.set", K::effect, {number, optional_table}, "dimmer", dimmer_level, &Lab::call_dimmer_set, &DryLab::call_dimmer_set},
      {"lamps.names", K::reading, {}, "lamps", nullptr, &Lab::call_lamps_names, &DryLab::call_lamps_names},
      {"lamps.off", K::effect, {}, "lamps", nullptr, &Lab::call_lamps_off, &DryLab::call_lamps_off},
      {"lamps.select", K::effect, {string}, "lamps", nullptr, &Lab::call_lamps_select, &DryLab::call_lamps_select},
      {"lamps.set", K::effect, {list}, "lamps", nullptr, &Lab::call_lamps_set, &DryLab::call_lamps_set},
      {"meter.measure", K::reading, {}, "luminance_meter", nullptr, &Lab::call_meter_measure, &DryLab::call_meter_measure},
      {"now", K::reading, {}, "", nullptr, &Lab::call_now, &DryLab::call_now},
      {"operator.request", K::reading, {table}, "", nullptr, &Lab::call_operator_request, &DryLab::call_operator_request},
      {"runs.chart_reference", K::reading, {string}, "", nullptr, &Lab::call_runs_chart_reference, &DryLab::call_runs_chart_reference},
      {"spectro.calibrate", K::effect, {}, "spectrophotometer", nullptr, &Lab::call_spectro_calibrate, nullptr},
      {"spectro.measure", K::reading, {}, "spectrophotometer", nullptr, &Lab::call_spectro_measure, &DryLab::call_spectro_measure},
      {"spectro.mode", K::effect, {string}, "spectrophotometer", nullptr, &Lab::call_spectro_mode, &DryLab::call_spectro_mode},
      {"table.head_down", K::effect, {}, "table", nullptr, &Lab::call_table_head_down, nullptr},
      {"table.head_up", K::effect, {}, "table", nullptr, &Lab::call_table_head_up, nullptr},
      {"table.hold_paper", K::effect, {boolean}, "table", nullptr, &Lab::call_table_hold_paper, nullptr},
      {"table.home", K::effect, {}, "table", nullptr, &Lab::call_table_home, nullptr},
      {"table.measure_at", K::reading, {number, number}, "table", nullptr, &Lab::call_table_measure_at, &DryLab::call_table_measure_at},
      {"table.move", K::effect, {number, number}, "table", nullptr, &Lab::call_table_move, &DryLab::call_table_move},
      {"table.read_patch", K::reading, {number, number, optional_table}, "table", nullptr, &Lab::call_table_read_patch,
       &DryLab::call_table_read_patch},
      {"wait", K::effect, {number}, "", wait_seconds, &Lab::call_wait, nullptr},
      {"wait_stable", K::reading, {optional_table}, "luminance_meter", nullptr, &Lab::call_wait_stable, &DryLab::call_wait_stable},
  });
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
