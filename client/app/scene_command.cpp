#include "scene_command.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "client_support.hpp"
#include "daemon_lenses.hpp"
#include "lens_option.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/verify/cabinet_json.hpp"
#include "colorlab/verify/cabinet_toml.hpp"
#include "colorlab/verify/scene_export.hpp"

namespace colorlab::cli {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

struct SceneOptions {
  std::vector<std::string> runs;
  std::string output;
  std::string lab;
  std::vector<std::string> lamps;
  double dimmer = 100.0;
  std::string lens;
  std::string lens_calibration;
};

// A run is its id (fetched as the daemon's JSON export) or a file holding that export, so a scene can be made
// where the daemon is not, from `colorlab export RUN -f json` files.
json load_run(const GlobalOptions& g, const std::string& run) {
  std::error_code ec;
  if (fs::is_regular_file(run, ec)) {
    std::ifstream f(run, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    try {
      return json::parse(ss.str());
    } catch (const json::exception& e) {
      throw Error(ErrorClass::bad_data, run + ": not JSON (" + e.what() + ")", "give a file from colorlab export RUN -f json");
    }
  }
  check_id(run, "a run id or a run's JSON export file", "colorlab runs lists them");
  return make_client(g).get("/v1/runs/" + run + "/export?format=json");  // a body that is not JSON: Error, not a crash
}

bool is_file(const std::string& run) {
  std::error_code ec;
  return fs::is_regular_file(run, ec);
}

// --lab FILE; else the daemon's own [cabinet] when the runs come from it (the lab's box, not a guess); else, for
// run files made away from the daemon, the built-in cabinet. Says which.
std::pair<verify::CabinetGeometry, std::string> choose_cabinet(const GlobalOptions& g, const SceneOptions& o) {
  if (!o.lab.empty()) return {verify::cabinet_from_file(o.lab), "lab file " + o.lab};
  if (std::all_of(o.runs.begin(), o.runs.end(), is_file)) return {verify::default_cabinet(), "built-in"};
  const json answer = make_client(g).get("/v1/lab/cabinet");
  if (!answer.is_object() || !answer.contains("cabinet"))
    throw Error(ErrorClass::bad_data, "GET /v1/lab/cabinet: no cabinet in the daemon's answer", "give the cabinet with --lab FILE");
  return {verify::cabinet_from_json(answer["cabinet"], "GET /v1/lab/cabinet"),
          "daemon (" + answer.value("source", std::string("?")) + ")"};
}

// The lab's stored lens calibrations, from where the cabinet comes from: --lab's [[lens]]; the daemon's
// (GET /v1/lab/lenses) when the runs come from it; none for run files alone, or from a daemon that serves none
// (said so; naming one with --lens-calibration there is refused).
std::pair<std::vector<verify::LensCalibration>, std::string> lab_lenses(const GlobalOptions& g, const SceneOptions& o) {
  if (!o.lab.empty()) return {verify::lenses_from_file(o.lab), "lab file " + o.lab};
  if (std::all_of(o.runs.begin(), o.runs.end(), is_file)) return {{}, "none (run files only)"};
  auto served = daemon_lenses(make_client(g));
  if (served) return {std::move(*served), "daemon"};
  if (!o.lens_calibration.empty())
    throw Error(ErrorClass::not_found, "--lens-calibration \"" + o.lens_calibration + "\": " + kNoLensRoute,
                "give the lens with --lens fx,fy,cx,cy,k1,k2, or the lab file holding it with --lab FILE");
  return {{}, std::string("none (") + kNoLensRoute + ")"};
}

}  // namespace

void add_scene_command(CLI::App& app, GlobalOptions& global) {
  auto o = std::make_shared<SceneOptions>();
  auto* cmd = app.add_subcommand(
      "scene",
      "Export the measured scene for a renderer: DIR/scene.json (cabinet, lamps, chart spectra, camera, LS-110 "
      "scale) and DIR/build_scene.py (Blender: blender -b --factory-startup -noaudio -P DIR/build_scene.py)");
  cmd->add_option("runs", o->runs, "a chart-read run, for the lamps' levels a cabinet-grid run, for the camera's pose a characterize-camera run (ids or JSON export files)")
      ->required();
  cmd->add_option("-o,--output", o->output, "directory to write (created)")->required();
  cmd->add_option("--lab", o->lab,
                  "TOML file whose [cabinet] table describes the cabinet (default: the daemon's [cabinet] when runs come "
                  "from it, else the built-in cabinet)");
  cmd->add_option("--lamp", o->lamps, "lamp to light (repeatable; default: those the cabinet-grid run measured)");
  cmd->add_option("--dimmer", o->dimmer, "dimmer level whose LS-110 readings set the lamps' levels (%)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  cmd->add_option("--lens", o->lens,
                  "the lab's lens calibration fx,fy,cx,cy[,k1,k2] (pixels of the located photograph), for the camera's "
                  "intrinsics with a characterize-camera run's pose; overrides the stored calibrations (default: the lab's "
                  "[[lens]] calibration for the photograph's size, else a nominal 50 mm lens, said so in scene.json)");
  cmd->add_option("--lens-calibration", o->lens_calibration,
                  "the stored lens calibration to use, by name (colorlab lens list), when several fit the photograph");
  cmd->callback([&global, o] {
    const auto [cabinet, cabinet_source] = choose_cabinet(global, *o);
    std::vector<json> runs;
    for (const auto& r : o->runs) runs.push_back(load_run(global, r));
    verify::SceneExportOptions so{o->lamps, o->dimmer, parse_lens(o->lens), "", {}, o->lens_calibration};
    std::string lenses_from = "not consulted (--lens given)";
    if (so.lens) so.lens_source = "lens calibration given with --lens";
    else std::tie(so.lenses, lenses_from) = lab_lenses(global, *o);
    const json scene = verify::export_scene(cabinet, runs, so);
    verify::write_scene(scene, o->output);
    json lamps = json::array();
    for (const auto& l : scene["lamps"]) lamps.push_back({
        {"name", l["name"]},
        {"luminance_cd_m2", l["luminance_cd_m2"]},
        {"level", l["level"]["source"]},
    });
    json done{
        {"directory", o->output},
        {"files", {"scene.json", "build_scene.py"}},
        {"lamps", lamps},
        {"patches", scene["chart"]["patches"].size()},
        {"cabinet", cabinet_source},
        {"lens_calibrations", lenses_from},
        {"intrinsics", scene["camera"].value("intrinsics_source", std::string())},
    };
    print(global, done, [](const json& j) {
      std::string s = "wrote " + j["directory"].get<std::string>() + "/scene.json and build_scene.py (" +
                      std::to_string(j["patches"].get<std::size_t>()) + " patches";
      for (const auto& l : j["lamps"])
        s += ", " + l["name"].get<std::string>() + " " + std::to_string(l["luminance_cd_m2"].get<double>()) + " cd/m² (" +
             l["level"].get<std::string>() + ")";
      s += "; cabinet: " + j["cabinet"].get<std::string>() + "; camera intrinsics: " + j["intrinsics"].get<std::string>();
      return s + ")\nrender: blender -b --factory-startup -noaudio -P " + j["directory"].get<std::string>() +
             "/build_scene.py -- --mode bands\n";
    });
  });
}

}  // namespace colorlab::cli
