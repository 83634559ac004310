#pragma once
// The stability suite: where each characterization method fails. Every method is fitted and driven into the
// regions that break characterizations — patches outside the training gamut, noise on the camera values, an
// exposure change, few training patches, another lamp than the one trained under — and each case's ΔE00 is
// summarised and judged against a stated tolerance.
//
//   StabilityOptions o;                       // methods, tolerance, noise levels, exposures, sizes, draws, seed
//   StabilityResult r = run_stability(train, o, &test_chart, {{"TL84", under_tl84}});
//   for (const auto& c : r.cases) ...         // per method per case: ΔE00 summary, fitted, fails
//   for (const auto& v : r.verdicts) ...      // per method: the first case that fails
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "colorlab/analysis/regression.hpp"
#include "colorlab/analysis/statistics.hpp"

namespace colorlab::analysis {

struct StabilityOptions {
  // Any fit_method name: poly:N, hong:N, rootpoly:D, ccm, rbf:<term set>.
  std::vector<std::string> methods = {"poly:1", "poly:6", "poly:10", "rootpoly:2"};
  FitOptions fit;             // target, ridge, input scale (0 = largest training value)
  CvSpec cv = CvSpec::loo();  // the cross-validated case (leave-one-out or k folds)
  // A case fails when a model could not be fitted, its mean ΔE00 exceeds `tolerance_mean` or its largest exceeds
  // `tolerance_max`. The defaults are the dissertation's: ΔE*ab 4–8 is acceptable depending on the application (§3.2,
  // after [Sha04]); §7.3 calls a polynomial acceptable when its maximum is close to 8. Applied here to ΔE00, which
  // reads below ΔE*ab on saturated colours: the same numbers are, if anything, the more lenient rule.
  double tolerance_mean = 4.0;
  double tolerance_max = 8.0;
  // Out of gamut: this share of the patches with the largest reference C*ab is held out and predicted by a model
  // trained on the rest (1/7: the SG's 20 most saturated of 140).
  double gamut_fraction = 1.0 / 7.0;
  // Noise: each camera value × (1 + σ·z), z ~ N(0, 1), for each relative σ; `draws` noisy copies per level.
  std::vector<double> noise = {0.001, 0.005, 0.01, 0.02};
  // Exposure change: the camera values × k; the chart's colours do not change, so the predicted XYZ is ÷ k.
  std::vector<double> exposures = {0.5, 2.0};
  // Camera values are clipped here after noise or an exposure change (0 = never: linear data without a ceiling).
  double saturation = 0;
  // Few training patches: `draws` random subsets of each size (sizes not below the chart's are skipped).
  std::vector<std::size_t> training_sizes = {70, 35, 24};
  int draws = 5;
  unsigned seed = 7;
};

// The kinds of case, in the order the suite runs them (and judges where a method first fails).
inline constexpr const char* kStabilityKinds[] = {"training", "cross_validated", "out_of_gamut", "noise", "exposure",
                                                  "training_patches", "other_lamp"};

struct StabilityCase {
  std::string method;
  std::string kind;           // one of kStabilityKinds
  double level = 0;           // noise: σ; exposure: k; training_patches: patches trained on; out_of_gamut: patches held
                              // out; training, cross_validated, other_lamp: patches evaluated
  std::string label;          // other_lamp: the lamp's name
  std::size_t evaluated = 0;  // ΔE00 values summarised (pooled over the draws)
  bool fitted = true;         // false: no model could be fitted (rank-deficient design); `why` says so
  std::string why;
  Summary de00;  // min/max/median/mean/stdev; mean = max = inf when not fitted
  bool fails = false;
  // Per patch where the case is one evaluation (training, cross_validated, out_of_gamut, exposure, other_lamp).
  std::vector<std::string> ids;
  std::vector<double> patch_de00;
};

struct StabilityVerdict {
  std::string method;
  bool fails = false;      // any case fails
  std::string first_kind;  // the first failing case in suite order ("" when none fails)
  double first_level = 0;
  std::string first_label;
};

struct StabilityResult {
  std::vector<StabilityCase> cases;  // per method, in suite order
  std::vector<StabilityVerdict> verdicts;
  StabilityOptions options;
  std::size_t gamut_held_out = 0;
  std::vector<std::string> gamut_ids;  // the patches held out as out of gamut
};

// `train`: the chart the models are fitted on. `test`: an independent chart to evaluate noise, exposure and few
// training patches on (nullptr: the training chart itself, and the patches left out for few training patches).
// `other_lamps`: (lamp, the same chart photographed under it with the same reference colours), matched by patch id.
// Throws Error(bad_parameter) for an unknown method or options out of range, Error(bad_data) for unusable charts.
StabilityResult run_stability(const ChartData& train, const StabilityOptions& options, const ChartData* test = nullptr,
                              const std::vector<std::pair<std::string, ChartData>>& other_lamps = {});

}  // namespace colorlab::analysis
