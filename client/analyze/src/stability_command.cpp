#include "stability_command.hpp"

#include <iostream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "analyze_output.hpp"
#include "colorlab/analysis/chart_io.hpp"
#include "colorlab/analysis/stability.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::cli::detail {
namespace {

namespace ca = colorlab::analysis;

struct StabilityCliOptions {
  std::string train, test, cv = "loo", target = "xyz";
  std::vector<std::string> other_lamps;
  ca::StabilityOptions suite;
  bool per_patch = false, json = false;
};

void run_stability(StabilityCliOptions o) {
  const ca::ChartData train = ca::read_chart(o.train);
  std::optional<ca::ChartData> test;
  if (!o.test.empty()) test = ca::read_chart(o.test);
  std::vector<std::pair<std::string, ca::ChartData>> others;
  for (const auto& spec : o.other_lamps) {
    const auto eq = spec.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size())
      throw Error(ErrorClass::bad_parameter, "--other-lamp '" + spec + "': expected LAMP=CHART, e.g. TL84=tl84.csv");
    others.emplace_back(spec.substr(0, eq), ca::read_chart(spec.substr(eq + 1)));
  }
  o.suite.cv = ca::CvSpec::parse(o.cv);
  o.suite.fit.target = o.target == "lab"    ? ca::FitTarget::lab_direct
                       : o.target == "xyzw" ? ca::FitTarget::xyz_lightness_weighted
                                            : ca::FitTarget::xyz_then_lab;
  const auto r = ca::run_stability(train, o.suite, test ? &*test : nullptr, others);

  Table cases{"cases", {
                           "method",
                           "case",
                           "level",
                           "label",
                           "evaluated",
                           "fitted",
                           "min",
                           "max",
                           "median",
                           "mean",
                           "stdev",
                           "fails",
                           "why",
                       },
              {}};
  Table patches{"patches", {"method", "case", "level", "label", "id", "dE00"}, {}};
  for (const auto& c : r.cases) {
    cases.rows.push_back({c.method, c.kind, c.level, c.label, double(c.evaluated), c.fitted ? 1.0 : 0.0, c.de00.min,
                          c.de00.max, c.de00.median, c.de00.mean, c.de00.stdev, c.fails ? 1.0 : 0.0, c.why});
    if (o.per_patch)
      for (std::size_t i = 0; i < c.ids.size(); ++i)
        patches.rows.push_back({c.method, c.kind, c.level, c.label, c.ids[i], c.patch_de00[i]});
  }
  Table verdicts{"verdicts", {"method", "fails", "first_failing_case", "level", "label"}, {}};
  for (const auto& v : r.verdicts)
    verdicts.rows.push_back({v.method, v.fails ? 1.0 : 0.0, v.first_kind, v.fails ? v.first_level : 0.0, v.first_label});
  const auto& s = r.options;
  Table settings{
      "settings",
      {
          "tolerance_mean",
          "tolerance_max",
          "target",
          "input_scale",
          "cv",
          "gamut_fraction",
          "gamut_held_out",
          "saturation",
          "draws",
          "seed",
          "training_patches",
          "test_patches",
      },
      {{
          s.tolerance_mean,
          s.tolerance_max,
          ca::to_string(s.fit.target),
          s.fit.input_scale,
          s.cv.name(),
          s.gamut_fraction,
          double(r.gamut_held_out),
          s.saturation,
          double(s.draws),
          double(s.seed),
          double(train.size()),
          test ? double(test->size()) : 0.0,
      }},
  };
  std::vector<Table> out{cases, verdicts, settings};
  if (o.per_patch) out.push_back(patches);
  print_tables(std::cout, out, o.json);
}

}  // namespace

void add_stability_command(CLI::App& analyze) {
  auto o = std::make_shared<StabilityCliOptions>();
  auto* c = analyze.add_subcommand(
      "stability",
      "Where each characterization method fails: fitted on a chart, then patches outside the training gamut, noise, "
      "an exposure change, few training patches and another lamp; ΔE00 per method per case, judged against a tolerance");
  c->add_option("--train", o->train, "Training chart: CSV (id,R,G,B,X,Y,Z and/or L,a,b) or Argyll .ti3")->required();
  c->add_option("--test", o->test, "Independent chart for the noise, exposure and few-patch cases (default: the training "
                                   "chart, and the patches left out)");
  c->add_option("--other-lamp", o->other_lamps, "LAMP=CHART: the same chart photographed under another lamp, same "
                                                "reference colours, matched by patch id (repeatable)");
  c->add_option("--methods", o->suite.methods, "Comma-separated: poly:1..11, hong:N, rootpoly:1..4, ccm, rbf:<term set>")
      ->delimiter(',')
      ->capture_default_str();
  c->add_option("--target", o->target, "xyz (fit XYZ, then L*a*b*), xyzw (lightness-weighted XYZ) or lab (direct)")
      ->check(CLI::IsMember({"xyz", "xyzw", "lab"}))
      ->capture_default_str();
  c->add_option("--input-scale", o->suite.fit.input_scale, "Divide RGB by this (0 = largest training value)")->capture_default_str();
  c->add_option("--cv", o->cv, "The cross-validated case: loo or kN (e.g. k10)")->capture_default_str();
  c->add_option("--tolerance", o->suite.tolerance_mean, "A case fails above this mean ΔE00 (the dissertation: 4-8 acceptable)")
      ->capture_default_str();
  c->add_option("--max-tolerance", o->suite.tolerance_max, "... or above this largest ΔE00")->capture_default_str();
  c->add_option("--noise", o->suite.noise, "Relative noise levels σ (camera value × (1 + σ·z)), comma-separated")
      ->delimiter(',')
      ->capture_default_str();
  c->add_option("--exposures", o->suite.exposures, "Exposure factors k (camera values × k, predicted XYZ ÷ k)")
      ->delimiter(',')
      ->capture_default_str();
  c->add_option("--saturation", o->suite.saturation, "Clip camera values here after noise or exposure (0 = never; 1 for "
                                                     "values scaled to full scale)")
      ->capture_default_str();
  c->add_option("--sizes", o->suite.training_sizes, "Training-set sizes for the few-patch case, comma-separated")
      ->delimiter(',')
      ->check(CLI::Range(std::size_t{1}, std::size_t{1000000}))
      ->capture_default_str();
  c->add_option("--gamut-fraction", o->suite.gamut_fraction, "Share of the most chromatic patches held out")->capture_default_str();
  c->add_option("--draws", o->suite.draws, "Random draws per noise level and training-set size")->capture_default_str();
  c->add_option("--seed", o->suite.seed, "Seed of the draws (a run is reproducible)")->capture_default_str();
  c->add_flag("--per-patch", o->per_patch, "Also each patch's ΔE00 where a case is one evaluation (table patches)");
  c->add_flag("--json", o->json, "JSON instead of CSV");
  c->callback([o] { run_stability(*o); });
}

}  // namespace colorlab::cli::detail
