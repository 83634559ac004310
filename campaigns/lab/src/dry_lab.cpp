#include "colorlab/campaigns/dry_lab.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "colorlab/campaigns/floor_photograph.hpp"
#include "dry_chart_centres.hpp"
#include "colorlab/campaigns/operator_desk.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/drivers/camera/camera_instrument.hpp"
#include "colorlab/drivers/lab_capabilities.hpp"
#include "colorlab/campaigns/roles.hpp"

namespace colorlab::campaigns {

using nlohmann::json;
using drivers::Capability;
namespace cam = drivers::camera;

namespace {

// A CIE XYZ (Y of white = 100) as camera values: linear sRGB primaries (IEC 61966-2-1) scaled to
// the format's code range. Only plausibility matters: the dry run fits the script's models to it.
std::array<double, 3> camera_values(const json& xyz, const std::string& format) {
  const double X = xyz[0].get<double>() / 100, Y = xyz[1].get<double>() / 100, Z = xyz[2].get<double>() / 100;
  std::array<double, 3> rgb{3.2406 * X - 1.5372 * Y - 0.4986 * Z, -0.9689 * X + 1.8758 * Y + 0.0415 * Z,
                            0.0557 * X - 0.2040 * Y + 1.0570 * Z};
  for (auto& v : rgb) {
    v = std::clamp(v, 0.002, 1.0);
    if (format == "raw") v = 3500 * v;  // DN above black of a 12-bit sensor, white well below clipping
    else if (format == "tiff16") v = 65535 * std::pow(v, 1 / 2.2);
    else v = 255 * std::pow(v, 1 / 2.2);
  }
  return rgb;
}

}  // namespace

std::string DryLab::role_of(const std::string& call) {
  const LabCall* c = find_lab_call(call);
  return c ? std::string(c->role) : std::string();
}

std::shared_ptr<drivers::Instrument> DryLab::instrument_for(const std::string& role) const {
  const Capability capability = capability_of(role);
  for (const auto& i : instruments_.all()) {
    if (!is_kind_for(i, role) || InstrumentSet::port_missing(*i)) continue;
    auto caps = i->capabilities();
    if (std::find(caps.begin(), caps.end(), capability) != caps.end()) return i;
  }
  for (const auto& i : instruments_.all()) {
    auto s = i->state();
    if (is_kind_for(i, role) && !InstrumentSet::port_missing(*i) &&
        (s == drivers::InstrumentState::disconnected || s == drivers::InstrumentState::initialising)) {
      return i;
    }
  }
  // Only an absent one (its port not there): the report names it and why, as the start would refuse.
  for (const auto& i : instruments_.all()) {
    if (is_kind_for(i, role)) return i;
  }
  return nullptr;
}

void DryLab::check_position(const std::string& call, const json& args, std::vector<DryProblem>& problems) const {
  auto table = std::dynamic_pointer_cast<drivers::XyTable>(instrument_for("table"));
  if (!table) return;
  auto travel = table->travel();
  if (!travel) return;
  const double x = args[0].get<double>(), y = args[1].get<double>();
  if (!(x >= 0 && x <= travel->x_max_mm && y >= 0 && y <= travel->y_max_mm)) {
    problems.push_back({"limit", "lab." + call + "(" + args[0].dump() + ", " + args[1].dump() + ") is outside " + table->id() +
                                     "'s travel (X 0–" + std::to_string(static_cast<int>(travel->x_max_mm)) + " mm, Y 0–" +
                                     std::to_string(static_cast<int>(travel->y_max_mm)) + " mm)"});
  }
}

json DryLab::grey_spectrum(const std::string& role) const {
  auto i = instrument_for(role);
  // A neutral 50 % reflector: XYZ of D50 × 0.5, L* 76.07.
  return json{{"mode", state_.spectro_mode.value_or("reflectance")},
              {"first_nm", 380},
              {"step_nm", 10},
              {"values", std::vector<double>(36, 0.5)},
              {"attempts", 1},
              {"instrument", i ? i->id() : std::string("dry-run")},
              {"XYZ", {48.21, 50.0, 41.245}},
              {"Lab", {76.07, 0.0, 0.0}}};
}

std::string DryLab::id_for(const std::string& role) const {
  auto i = instrument_for(role);
  return i ? i->id() : std::string("dry-run");
}

json DryLab::answer(const std::string& call, const json& args, double lab_now_s, std::vector<DryProblem>& problems) {
  const LabCall& c = lab_call(call);
  DryContext context{lab_now_s, problems};
  json result = c.dry_answer ? (this->*(c.dry_answer))(args, context) : json(nullptr);
  state_.apply(call, args, result);
  return result;
}

json DryLab::call_meter_measure(const json&, DryContext&) {
  return json{
      {"luminance", state_.dimmer_percent.value_or(100.0)},
      {"unit", "cd/m2"},
      {"instrument", id_for("luminance_meter")},
      {"raw", "dry run"},
  };
}

json DryLab::call_wait_stable(const json&, DryContext&) {
  return json{
      {"luminance", state_.dimmer_percent.value_or(100.0)},
      {"unit", "cd/m2"},
      {"instrument", id_for("luminance_meter")},
      {"drift_pct", 0.0},
      {"readings", 0},
      {"waited_s", 0.0},
  };
}

json DryLab::lamps_lit(std::vector<std::string> on, DryContext& context) const {
  if (auto lamps = std::dynamic_pointer_cast<drivers::LampController>(instrument_for("lamps"))) {
    auto names = lamps->lamp_names();
    for (const auto& l : on) {
      if (std::find(names.begin(), names.end(), l) == names.end()) {
        std::string known;
        for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
        context.problems.push_back({"limit", "lamp '" + l + "' is not one of " + lamps->id() + "'s lamps (" + known + ")"});
      }
    }
  }
  return json{{"lamps_on", on}};
}

json DryLab::call_lamps_select(const json& args, DryContext& context) {
  return lamps_lit({args[0].get<std::string>()}, context);
}

json DryLab::call_lamps_set(const json& args, DryContext& context) {
  std::vector<std::string> on;
  for (const auto& l : args[0]) {
    if (l.is_string()) on.push_back(l.get<std::string>());
  }
  return lamps_lit(on, context);
}

json DryLab::call_lamps_off(const json&, DryContext&) { return json{{"lamps_on", json::array()}}; }

json DryLab::call_lamps_names(const json&, DryContext&) {
  auto lamps = std::dynamic_pointer_cast<drivers::LampController>(instrument_for("lamps"));
  return lamps ? json(lamps->lamp_names()) : json::array();
}

json DryLab::call_dimmer_set(const json& args, DryContext& context) {
  const double level = args[0].get<double>();
  if (auto d = std::dynamic_pointer_cast<drivers::Dimmer>(instrument_for("dimmer"))) {
    auto [lo, hi] = d->level_range();
    if (level < 100 * lo - 1e-9 || level > 100 * hi + 1e-9) {
      context.problems.push_back({"limit", "lab.dimmer.set(" + args[0].dump() + "): " + d->id() + " holds levels from " +
                                               std::to_string(100 * lo) + " to " + std::to_string(100 * hi) + " %"});
    }
  }
  return json{{"dimmer_percent", args[0]}};
}

json DryLab::call_table_move(const json& args, DryContext& context) {
  check_position("table.move", args, context.problems);
  return nullptr;
}

json DryLab::call_table_measure_at(const json& args, DryContext& context) {
  check_position("table.measure_at", args, context.problems);
  return grey_spectrum("table");
}

json DryLab::call_table_read_patch(const json& args, DryContext& context) {
  check_position("table.read_patch", args, context.problems);
  return grey_spectrum("table");
}

json DryLab::call_spectro_mode(const json& args, DryContext&) {
  const auto mode = args[0].get<std::string>();
  if (mode != "reflectance" && mode != "emission" && mode != "transmission") {
    throw Error(ErrorClass::script_error, "lab.spectro.mode: '" + mode + "' is not reflectance, emission or transmission");
  }
  return nullptr;
}

json DryLab::call_spectro_measure(const json&, DryContext&) { return grey_spectrum("spectrophotometer"); }

json DryLab::call_camera_capture(const json& args, DryContext&) {
  const json o = args.empty() ? json::object() : args[0];
  const int frames = o.value("frames", 1);
  json rows = json::array();
  for (int n : {1, 2, 4, 8, 16, 25, 32, 64, 128, 256}) {
    if (n > frames) break;
    for (const char* c : {"R", "G", "B"}) rows.push_back({{"frames", n}, {"channel", c}, {"stdev", 8.0 / std::sqrt(n)}});
  }
  return json{
      {"frames", frames},
      {"region", {0, 0, 32, 32}},
      {"rows", rows},
      {"instrument", id_for("camera")},
      {"unit", "DN above black"},
  };
}

json DryLab::call_camera_photograph_chart(const json& args, DryContext&) {
  const json o = args.empty() || !args[0].is_object() ? json::object() : args[0];
  const int frames = o.value("frames", 25);
  json formats = o.contains("formats") && o["formats"].is_array() ? o["formats"] : json{"raw", "tiff16", "tiff8", "jpeg"};
  json ids = json::array(), xyz = json::array();
  if (o.contains("reference") && o["reference"].is_object() && o["reference"].contains("ids")) {
    ids = o["reference"]["ids"];
    xyz = o["reference"]["XYZ"];
  } else {
    for (int k = 0; k < 24; ++k) {
      ids.push_back(std::to_string(k + 1));
      const double y = 3 + 90.0 * k / 23;
      xyz.push_back({0.9642 * y, y, 0.8249 * y});
    }
  }
  json out = json{
      {"instrument", id_for("camera")},
      {"chart", o.value("chart", std::string("sg"))},
      {"frames", frames},
      {"formats", json::object()},
  };
  for (const auto& f : formats) {
    const std::string format = f.get<std::string>();
    json values = json::array();
    for (const auto& x : xyz) {
      auto v = camera_values(x, format);
      values.push_back({v[0], v[1], v[2]});
    }
    out["formats"][format] = json{
        {"format", format},
        {"bits", format == "raw" ? 16 : (format == "tiff16" ? 16 : 8)},
        {"confidence", 1.0},
        {"rotation_deg", 0},
        {"corners", json::array()},
        {"patches_detected", ids.size()},
        {"reprojection_rms_px", 0.0},
        {"check", json::object()},
        {"frames", frames},
        {"files", json::array()},
        {"width", 0},
        {"height", 0},
        {"notes", {"dry run: values from the reference"}},
        {"ids", ids},
        {"values", values},
        {"detected", std::vector<bool>(ids.size(), true)},
    };
    if (o.value("centres", false)) {
      // The chart where the last place_chart request put it, through an ideal lens (dry_chart_centres.hpp).
      out["formats"][format]["width"] = detail::kDryPhotoWidth, out["formats"][format]["height"] = detail::kDryPhotoHeight;
      out["formats"][format]["observed_px"] = detail::dry_chart_centres(chart_placed_, o.value("chart", std::string("sg")));
    }
  }
  return out;
}

json DryLab::call_camera_photograph_floor(const json& args, DryContext&) { return dry_floor_photograph(args[0], id_for("camera")); }

json DryLab::call_runs_chart_reference(const json& args, DryContext&) {
  if (!runs_) throw Error(ErrorClass::unsupported, "lab.runs.chart_reference: this lab keeps no runs to read");
  return chart_reference(*runs_, args[0].get<std::string>());
}

json DryLab::call_operator_request(const json& args, DryContext&) {
  OperatorRequest r = parse_operator_request(args[0]);
  if (r.action == "place_chart") chart_placed_ = r.details;
  // The first option is the one that says the action was done: the night as planned.
  return json{{"answer", r.options.front()}, {"by", "dry run"}, {"action", r.action}, {"details", r.details}};
}

json DryLab::call_now(const json&, DryContext& context) {
  if (start_unix_s_ == 0) {
    start_unix_s_ = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  }
  const double t = start_unix_s_ + context.lab_now_s;
  return json{{"utc", iso8601_utc(std::chrono::system_clock::time_point(std::chrono::duration_cast<std::chrono::system_clock::duration>(
                          std::chrono::duration<double>(t))))},
              {"unix", t}};
}

}  // namespace colorlab::campaigns
