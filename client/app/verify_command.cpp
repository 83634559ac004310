#include "verify_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <utility>

#include "client_support.hpp"
#include "daemon_lenses.hpp"
#include "lens_option.hpp"
#include "colorlab/client/runs.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/verify/compare/scene_from_runs.hpp"
#include "colorlab/verify/compare/stored.hpp"
#include "colorlab/verify/compare/stored_request.hpp"
#include "colorlab/verify/lens_calibration.hpp"
#include "colorlab/verify/rendering.hpp"
#ifdef COLORLAB_HAVE_VERIFY_COLOUR
#include "colour_from_runs.hpp"
#endif

namespace colorlab::cli {

using nlohmann::json;

namespace {

struct VerifyOptions {
  std::string rendering;
  std::vector<std::string> against;
  std::optional<double> scale;
  std::string lamp;
  std::optional<double> dimmer;
  double corner_accuracy_px = 0.5;
  std::string lens;
  std::string lens_calibration;
  bool no_rendering_noise = false;
  int noise_neighbours = verify::CompareOptions{}.noise_neighbours;  // the library's default, shown in --help
  bool json = false;
  bool store = false;
};

std::string fixed(double x, int digits) {
  char s[64];
  std::snprintf(s, sizeof s, "%.*f", digits, x);
  return s;
}

// A difference in its kind's unit: ΔE00 for §7.3, percent for the relative ones.
std::string shown(const std::string& kind, double x) {
  return kind == "colour_7_3" ? fixed(x, 2) + " ΔE00" : fixed(100 * x, 2) + " %";
}

// The first eight items of a list, each after a space, and how many there are when that is not all of them.
template <class Describe>
void list_first_eight(std::ostringstream& out, const json& items, Describe describe) {
  std::size_t n = 0;
  for (const auto& item : items) {
    if (++n > 8) break;
    out << " " << describe(item);
  }
  if (items.size() > 8) out << " … (" << items.size() << " in all; --json lists them)";
}

std::string human(const json& j) {
  std::ostringstream out;
  const json& s = j["summary"];
  out << j["rendering"].get<std::string>() << " against " << j["against"].dump() << ": "
      << (s["verdict"] == "agrees" ? "AGREES" : "DIFFERS") << " within the measurement's uncertainty (k = 2)\n";
  for (const auto& sc : s["scales"])
    out << "  scale " << sc["kind"].get<std::string>() << ": " << sc["how"].get<std::string>() << " " << sc["factor"].get<double>()
        << (sc["how"] == "fitted" ? "  (a fitted factor cannot see a uniformly wrong level)" : "") << "\n";
  for (const auto& [kind, k] : s["kinds"].items()) {
    out << "  " << kind << ": " << k["agree"].get<int>() << "/" << k["compared"].get<std::size_t>() << " agree ("
        << fixed(100 * k["agree_fraction"].get<double>(), 1) << " %), median |difference| "
        << shown(kind, k["median_abs_difference"].get<double>());
    if (k.contains("worst"))
      out << ", worst " << k["worst"]["where"].get<std::string>() << " " << shown(kind, k["worst"]["difference"].get<double>())
          << " (band ±" << shown(kind, k["worst"]["expanded"].get<double>()) << ")";
    out << "\n";
    const json& wrong = k["renderer_wrong_at"];
    if (!wrong.empty()) {
      out << "    renderer differs at:";
      list_first_eight(out, wrong, [&](const json& w) {
        return w["where"].get<std::string>() + " " + shown(kind, w["difference"].get<double>());
      });
      out << "\n";
    }
    // The noise screen's verdict is part of the result: a region judged on its own spread says where the band
    // came from when it is wider than its neighbours'.
    if (k.contains("rendering_noise_left_out") && !k["rendering_noise_left_out"].empty()) {
      out << "    the rendering's noise judged on its own at:";
      list_first_eight(out, k["rendering_noise_left_out"], [](const json& where) { return where.get<std::string>(); });
      out << " (its band there is its own spread, kept out of its neighbours' pools)\n";
    }
    const json& blind = k["measurement_cannot_tell_at"];
    if (!blind.empty())
      out << "    the measurement cannot tell at " << blind.size() << " (band wider than the cannot-tell limit; --json names "
          << "the dominant source)\n";
  }
  if (j.contains("not_compared"))
    for (const auto& [kind, why] : j["not_compared"].items()) out << "  " << kind << " not compared: " << why.get<std::string>() << "\n";
  if (j.contains("placement") && j["placement"].contains("light"))
    out << "  floor placed: " << j["placement"]["light"]["how"].get<std::string>() << "\n";
  if (j.contains("rendering_noise") && !j["rendering_noise"].get<bool>())
    out << "  the rendering's own noise: not in the budget (--no-rendering-noise: the renderer states it is exact)\n";
  if (j.contains("stored_run")) out << "  stored as run " << j["stored_run"].get<std::string>() << "\n";
  return out.str();
}

// The floor photograph's size: the floor-luminance run's photograph rows (P/…) all come from its one camera.
std::optional<std::pair<int, int>> floor_photograph_size(const std::vector<json>& runs) {
  for (const auto& run : runs) {
    if (run.value("campaign", "") != "floor-luminance" || !run.contains("measurements")) continue;
    for (const auto& m : run["measurements"]) {
      if (m.value("step", "").rfind("P/", 0) != 0 || !m.contains("data") || !m["data"].is_object()) continue;
      const json& d = m["data"];
      if (d.contains("width") && d["width"].is_number() && d.contains("height") && d["height"].is_number())
        return std::pair{d["width"].get<int>(), d["height"].get<int>()};
    }
  }
  return std::nullopt;
}

// Where the light half's floor lies in the rendering: through the lens the floor was photographed with — --lens, or
// the lab's stored calibration (GET /v1/lab/lenses) for the photograph's size — else as a pinhole, and said which
// (`placement.light`, also stored), as when the daemon serves no calibrations at all (a 404: daemon_lenses.hpp).
// Nothing to place without a floor-luminance run: null.
json place_light(client::ApiClient& api, const VerifyOptions& o, const std::vector<json>& runs, verify::RunsSceneOptions& so) {
  const auto size = floor_photograph_size(runs);
  if (!size) {
    if (!o.lens.empty() || !o.lens_calibration.empty())
      throw Error(ErrorClass::bad_parameter, "--lens and --lens-calibration place the floor photograph, and no floor-luminance run with a photograph was given",
                  "give the floor-luminance run with --against");
    return nullptr;
  }
  const auto [w, h] = *size;
  const std::string frame = std::to_string(w) + " × " + std::to_string(h);
  std::optional<verify::CameraIntrinsics> k = parse_lens(o.lens);
  std::string name = k ? "given with --lens" : "", described = k ? "lens given with --lens" : "";
  std::optional<std::vector<verify::LensCalibration>> lenses;
  if (!k) {
    lenses = daemon_lenses(api);
    if (!lenses && !o.lens_calibration.empty())
      throw Error(ErrorClass::not_found, "--lens-calibration \"" + o.lens_calibration + "\": " + kNoLensRoute,
                  "give the lens's numbers with --lens fx,fy,cx,cy,k1,k2 (colorlab lens list --lab FILE shows a lab file's)");
  }
  if (lenses) {
    if (const auto l = verify::choose_lens(*lenses, o.lens_calibration, w, h)) {
      if (l->width_px != w || l->height_px != h)
        throw Error(ErrorClass::bad_parameter,
                    "lens calibration \"" + l->name() + "\" holds for " + std::to_string(l->width_px) + " × " + std::to_string(l->height_px) +
                        " photographs, the floor photograph is " + frame,
                    "name the calibration of the floor camera (colorlab lens list)");
      k = l->intrinsics;
      name = l->name();
      described = "lens calibration \"" + name + "\" (" + l->source + ", " + l->date + ")";
    }
  }
  if (!k) {
    const std::string none = lenses ? "no lens calibration for " + frame + " photographs (GET /v1/lab/lenses)" : std::string(kNoLensRoute);
    const std::string why = none + ": the floor photograph's corners taken as a pinhole camera's; "
                                   "a distorted lens misplaces spots towards the frame's edges";
    return {{"light", {
                          {"model", "pinhole"},
                          {"lens", nullptr},
                          {"how", why},
                      }}};
  }
  so.lens = verify::PhotographLens{k->fx, k->fy, k->cx, k->cy, k->k1, k->k2, described};
  const std::string how = "the floor photograph's corners undistorted through the " + described + "; the rendering taken as that camera's pinhole";
  return {{"light", {
                        {"model", "lens calibration"},
                        {"lens", {
                                     {"name", name},
                                     {"width_px", w},
                                     {"height_px", h},
                                     {"fx", k->fx},
                                     {"fy", k->fy},
                                     {"cx", k->cx},
                                     {"cy", k->cy},
                                     {"k1", k->k1},
                                     {"k2", k->k2},
                                 }},
                        {"how", how},
                    }}};
}

int verify(const GlobalOptions& global, const VerifyOptions& o) {
  verify::CompareOptions options;
  options.scale = o.scale;
  options.rendering_noise = !o.no_rendering_noise;
  options.noise_neighbours = o.noise_neighbours;
  verify::check_options(options);  // before the file and the daemon: a bad option is the first thing said
  // The file first: a rendering that cannot be read is a local error (exit 1) whatever the daemon says.
  const verify::Rendering rendering = verify::read_rendering(o.rendering);
  auto api = make_client(global);
  std::vector<json> runs;
  for (const auto& id : o.against) {
    check_id(id, "a run id", "colorlab runs lists them");
    runs.push_back(client::fetch_run(api, id));
  }
#ifdef COLORLAB_HAVE_VERIFY_COLOUR
  // A characterization is read with the chart-read it was fitted against (the patches' spectra): fetched here
  // when not given, so `--against CHARACTERIZE_RUN` is enough for the colour.
  const std::size_t given = runs.size();
  for (std::size_t i = 0; i < given; ++i) {
    const std::string ref = verify::chart_read_of(runs[i]);
    if (ref.empty()) continue;
    const bool have = std::any_of(runs.begin(), runs.end(), [&](const json& r) { return r.value("id", "") == ref; });
    if (!have) runs.push_back(client::fetch_run(api, ref));
  }
#endif
  verify::RunsSceneOptions scene_options;
  scene_options.corner_accuracy_px = o.corner_accuracy_px;
  if (!o.lamp.empty() || o.dimmer) {
    if (o.lamp.empty() || !o.dimmer)
      throw Error(ErrorClass::bad_parameter, "--lamp and --dimmer go together", "e.g. --lamp D65 --dimmer 100");
    scene_options.light = verify::LightSelection{o.lamp, *o.dimmer};
  }
  const json placement = place_light(api, o, runs, scene_options);
#ifdef COLORLAB_HAVE_VERIFY_COLOUR
  json colour;
  const auto scene = verify::measured_scene_from_runs(runs, rendering, scene_options, &colour);
#else
  const auto scene = verify::scene_from_runs(runs, rendering.width, rendering.height, scene_options);
#endif
  const auto v = verify::compare(rendering, scene, options);

  const std::string name = std::filesystem::path(o.rendering).filename().string();
  json out = v.to_json();
  out["rendering"] = name;
  out["against"] = o.against;
  out["lamp"] = scene.lamp;
  out["exit_status"] = verify::exit_status(v);
  out["rendering_noise"] = options.rendering_noise;
  out["noise_neighbours"] = options.rendering_noise ? json(options.noise_neighbours) : json(nullptr);
  out["noise_pooling"] = options.rendering_noise ? json(verify::kNoisePooling) : json(nullptr);
  if (!placement.is_null()) out["placement"] = placement;
#ifdef COLORLAB_HAVE_VERIFY_COLOUR
  if (!colour.is_null()) out["colour"] = colour;
#endif
  // A comparison the runs allow but the rendering does not is said, not silently left out.
  if (scene.characterization && rendering.encoding != verify::Encoding::spectral)
    out["not_compared"]["colour_7_4"] = "the rendering is not spectral: §7.4 takes each band's radiance through the camera's "
                                        "sensitivities (render the bands, e.g. colorlab scene's --mode bands)";
  if (o.store) {
    const json stored = api.post("/v1/verifications", verify::store_request(v, name, o.against, options, placement));
    out["stored_run"] = stored.at("run_id");
  }
  GlobalOptions g = global;
  g.json = global.json || o.json;
  print(g, out, human);
  return verify::exit_status(v);
}

}  // namespace

void add_verify_command(CLI::App& app, GlobalOptions& global) {
  auto o = std::make_shared<VerifyOptions>();
  auto* cmd = app.add_subcommand(
      "verify",
      "Compare a rendering (OpenEXR spectral/XYZ/RGB, Radiance .hdr, PFM) with the measured scene of cabinet-grid and "
      "floor-luminance runs (light) and a characterize-camera run (colour, §7.3 and §7.4), within the measurement's uncertainty "
      "(k = 2). Exit 0 agrees, 4 differs, 1 local error, 2 API refused");
  cmd->add_option("rendering", o->rendering, "the rendering file, made with the exported camera (the floor photograph's view)")
      ->required();
  cmd->add_option("--against", o->against, "run ids: one floor-luminance run (where the floor lies) and optionally one cabinet-grid run; one "
                                           "characterize-camera run for the colour (its chart-read is fetched with it)")
      ->required();
  cmd->add_option("--scale", o->scale,
                  "renderer unit -> cd/m² (1 for W·m⁻²·sr⁻¹·nm⁻¹ spectral and cd/m² XYZ); omitted: one factor fitted per kind, "
                  "which cannot see a uniformly wrong level")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--lamp", o->lamp, "the lamp to compare under (default: the floor-luminance run's first)");
  cmd->add_option("--dimmer", o->dimmer, "its dimmer level in % (with --lamp)")->check(CLI::Range(0.0, 100.0));
  cmd->add_option("--corner-accuracy-px", o->corner_accuracy_px,
                  "how well the floor's corners are known on the photograph, one σ in its pixels (the misregistration)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--lens", o->lens,
                  "the floor camera's lens fx,fy,cx,cy[,k1,k2] (OpenCV's model, pixels of the floor photograph): the floor is placed "
                  "in the rendering through it; overrides the stored calibrations (default: the lab's [[lens]] for the floor "
                  "photograph's size, else a pinhole, said in `placement`)");
  cmd->add_option("--lens-calibration", o->lens_calibration,
                  "the stored lens calibration to place the floor through, by name (colorlab lens list), when several fit");
  cmd->add_flag("--no-rendering-noise", o->no_rendering_noise,
                "leave the rendering's own Monte-Carlo noise out of the budget: only for a renderer that states its image is "
                "exact (noise-free); recorded in the result and a stored verification");
  cmd->add_option("--noise-neighbours", o->noise_neighbours,
                  "the rendering's noise level is pooled over this many nearest regions of a kind (≥ 1; regions whose "
                  "residuals are not their neighbours' noise are left out)")
      ->capture_default_str();
  cmd->add_flag("--json", o->json, "print the whole result: summary, every comparison with its budget, floor_difference");
  cmd->add_flag("--store", o->store, "store the verification on the daemon as a `verify` run (POST /v1/verifications)");
  cmd->callback([&global, o] {
    const int rc = verify(global, *o);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace colorlab::cli
