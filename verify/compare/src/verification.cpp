#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "colorlab/core/error.hpp"
#include "comparisons.hpp"

namespace colorlab::verify {

std::string_view to_string(Verdict v) { return v == Verdict::agrees ? "agrees" : "differs"; }

void check_options(const CompareOptions& options) {
  if (options.scale && !(*options.scale > 0))
    throw Error(ErrorClass::bad_parameter, "a given scale must be a positive number (renderer unit -> cd/m²)");
  if (!(options.k > 0)) throw Error(ErrorClass::bad_parameter, "the coverage factor k must be positive");
  if (options.noise_neighbours < 1)
    throw Error(ErrorClass::bad_parameter,
                "noise_neighbours must be at least 1 (got " + std::to_string(options.noise_neighbours) + ")",
                "the rendering's noise level is pooled over that many nearest regions of a kind (default 8); to leave the "
                "rendering's noise out of the budget, turn it off (--no-rendering-noise, \"rendering_noise\": false)");
}

Verification compare(const Rendering& rendering, const MeasuredScene& scene, const CompareOptions& options) {
  if (rendering.width <= 0 || rendering.height <= 0 || rendering.pixels.empty())
    throw Error(ErrorClass::bad_data, "the rendering has no pixels");
  check_options(options);
  Verification v;
  bool any = false;
  if (scene.characterization && !scene.patches.empty()) {
    detail::compare_colour_73(rendering, scene, options, v);
    any = true;
  }
  if (scene.black_box && !scene.patches.empty() && rendering.encoding == Encoding::spectral) {
    detail::compare_colour_74(rendering, scene, options, v);
    any = true;
  }
  if (!scene.spots.empty() || !scene.floor.empty()) {
    detail::compare_light(rendering, scene, options, v);
    any = true;
  }
  if (!any)
    throw Error(ErrorClass::bad_parameter, "nothing to compare: the runs give no patches with a characterization, no LS-110 spots and no floor map",
                "verify against a characterize-camera run (with its chart-read), a cabinet-grid run or a floor-luminance run");
  return v;
}

bool Verification::differs() const {
  return std::any_of(comparisons.begin(), comparisons.end(), [](const Comparison& c) { return c.verdict == Verdict::differs; });
}

nlohmann::json Verification::summary() const {
  nlohmann::json kinds = nlohmann::json::object();
  std::map<std::string, std::vector<const Comparison*>> by_kind;
  for (const auto& c : comparisons) by_kind[c.kind].push_back(&c);
  for (const auto& [kind, list] : by_kind) {
    nlohmann::json k;
    int differ = 0, cannot = 0;
    std::vector<double> diffs;
    const Comparison* worst = nullptr;
    nlohmann::json wrong = nlohmann::json::array(), blind = nlohmann::json::array(), own = nlohmann::json::array();
    for (const auto* c : list) {
      diffs.push_back(std::abs(c->difference));
      if (c->noise_left_out) own.push_back(c->where);
      if (c->verdict == Verdict::differs) {
        ++differ;
        wrong.push_back({{"where", c->where}, {"difference", c->difference}, {"expanded", c->expanded}});
        if (!worst || c->mahalanobis / c->threshold > worst->mahalanobis / worst->threshold) worst = c;
      }
      if (c->cannot_tell) {
        ++cannot;
        // The source that dominates there is what to improve in the measurement.
        const auto top = std::max_element(c->budget.begin(), c->budget.end(),
                                          [](const auto& a, const auto& b) { return a.second < b.second; });
        blind.push_back({
            {"where", c->where},
            {"expanded", c->expanded},
            {"dominant_source", top == c->budget.end() ? "" : top->first},
        });
      }
    }
    std::sort(diffs.begin(), diffs.end());
    k["compared"] = list.size();
    k["agree"] = static_cast<int>(list.size()) - differ;
    k["differ"] = differ;
    k["agree_fraction"] = list.empty() ? 1.0 : 1.0 - static_cast<double>(differ) / static_cast<double>(list.size());
    k["median_abs_difference"] = diffs.empty() ? 0.0 : diffs[diffs.size() / 2];
    k["renderer_wrong_at"] = wrong;
    k["measurement_cannot_tell_at"] = blind;
    // Where the rendering-noise screen judged a region's residuals not the noise its neighbours share: its band
    // there is its own spread (wide when it is the scene's texture), and it was kept out of the others' pools.
    k["rendering_noise_left_out"] = own;
    if (worst) k["worst"] = {{"where", worst->where}, {"difference", worst->difference}, {"expanded", worst->expanded}};
    kinds[kind] = k;
  }
  nlohmann::json scales_json = nlohmann::json::array();
  for (const auto& s : scales) scales_json.push_back({{"kind", s.kind}, {"how", s.how}, {"factor", s.factor}});
  return {{"verdict", differs() ? "differs" : "agrees"}, {"coverage_k", 2}, {"kinds", kinds}, {"scales", scales_json}};
}

nlohmann::json Verification::to_json() const {
  nlohmann::json items = nlohmann::json::array();
  for (const auto& c : comparisons) {
    nlohmann::json budget = nlohmann::json::object();
    for (const auto& [name, u] : c.budget) budget[name] = u;
    items.push_back({
        {"kind", c.kind},
        {"where", c.where},
        {"rendered", c.rendered},
        {"measured", c.measured},
        {"difference", c.difference},
        {"expanded", c.expanded},
        {"mahalanobis", c.mahalanobis},
        {"threshold", c.threshold},
        {"verdict", to_string(c.verdict)},
        {"cannot_tell", c.cannot_tell},
        {"noise_left_out", c.noise_left_out},
        {"budget", budget},
    });
  }
  nlohmann::json floor = nlohmann::json::array();
  for (const auto& row : floor_ratio) {
    nlohmann::json r = nlohmann::json::array();
    for (double x : row) r.push_back(std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr));
    floor.push_back(r);
  }
  return {{"summary", summary()}, {"comparisons", items}, {"floor_difference", floor}};
}

}  // namespace colorlab::verify
