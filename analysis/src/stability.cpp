#include "colorlab/analysis/stability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "colorlab/analysis/characterization.hpp"
#include "colorlab/analysis/polynomial_terms.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void check_options(const StabilityOptions& o) {
  if (o.methods.empty()) throw Error(ErrorClass::bad_parameter, "stability: no methods given");
  for (const auto& m : o.methods) {
    // Unknown names are refused before any fit, not reported as "not fitted".
    if (m.rfind("rbf:", 0) == 0) term_set_by_name(m.substr(4));
    else term_set_by_name(m);
  }
  if (!(o.tolerance_mean > 0) || !(o.tolerance_max > 0))
    throw Error(ErrorClass::bad_parameter, "stability: the tolerances must be positive ΔE00");
  if (!(o.gamut_fraction > 0 && o.gamut_fraction < 1))
    throw Error(ErrorClass::bad_parameter, "stability: the out-of-gamut share must lie between 0 and 1");
  for (double s : o.noise)
    if (!(s >= 0 && std::isfinite(s))) throw Error(ErrorClass::bad_parameter, "stability: a noise level must be ≥ 0");
  for (double k : o.exposures)
    if (!(k > 0 && std::isfinite(k))) throw Error(ErrorClass::bad_parameter, "stability: an exposure factor must be > 0");
  if (o.draws < 1) throw Error(ErrorClass::bad_parameter, "stability: draws must be at least 1");
  if (o.cv.kind == CvSpec::Kind::none)
    throw Error(ErrorClass::bad_parameter, "stability: the cross-validated case needs leave-one-out or k folds, not none");
  if (o.saturation < 0) throw Error(ErrorClass::bad_parameter, "stability: the saturation level must be ≥ 0");
}

Eigen::MatrixXd clipped(Eigen::MatrixXd rgb, double saturation) {
  if (saturation > 0) rgb = rgb.cwiseMin(saturation);
  return rgb;
}

StabilityCase not_fitted(StabilityCase c, const std::string& why) {
  c.fitted = false;
  c.why = why;
  c.de00 = Summary{};
  c.de00.min = c.de00.max = c.de00.median = c.de00.mean = c.de00.stdev = kInf;
  return c;
}

void judge(StabilityCase& c, const StabilityOptions& o) {
  c.fails = !c.fitted || !(c.de00.mean <= o.tolerance_mean) || !(c.de00.max <= o.tolerance_max);
}

// One evaluation: the ΔE00 of each patch, kept per patch.
void set_patches(StabilityCase& c, const std::vector<std::string>& ids, const std::vector<double>& de00) {
  c.ids = ids;
  c.patch_de00 = de00;
  c.evaluated = de00.size();
  c.de00 = summarize(de00);
}

// Pooled over draws.
void set_pooled(StabilityCase& c, const std::vector<double>& de00) {
  c.evaluated = de00.size();
  c.de00 = summarize(de00);
}

// The model's L*a*b* for camera values taken at k × the training exposure: the colours are the chart's, so the
// predicted XYZ is divided by k (a model fitted to L*a*b* goes through XYZ for it).
Eigen::MatrixXd predict_at_exposure(const Characterization& m, const Eigen::MatrixXd& rgb, double k,
                                    const FitOptions& fit, const Xyz& white) {
  const Eigen::MatrixXd target = m.predict_target(rgb);
  Eigen::MatrixXd xyz(target.rows(), 3);
  if (fit.target == FitTarget::lab_direct) {
    for (Eigen::Index i = 0; i < target.rows(); ++i) {
      const Xyz x = lab_to_xyz(Lab{target(i, 0), target(i, 1), target(i, 2)}, white);
      xyz.row(i) << x.X, x.Y, x.Z;
    }
  } else {
    xyz = target;
  }
  return xyz_rows_to_lab(xyz / k, white);
}

std::vector<std::size_t> rows_by_id(const ChartData& of, const std::vector<std::string>& ids) {
  std::vector<std::size_t> rows;
  for (const auto& id : ids) {
    auto it = std::find(of.ids.begin(), of.ids.end(), id);
    if (it != of.ids.end()) rows.push_back(static_cast<std::size_t>(it - of.ids.begin()));
  }
  return rows;
}

class Suite {
 public:
  Suite(const ChartData& train, const StabilityOptions& o, const ChartData* test,
        const std::vector<std::pair<std::string, ChartData>>& others)
      : train_(train), o_(o), test_(test ? *test : train), independent_(test != nullptr), others_(others) {}

  StabilityResult run() {
    StabilityResult r;
    r.options = o_;
    gamut_split(r);
    for (const auto& m : o_.methods) {
      std::mt19937 rng(o_.seed);  // each method sees the same noise and the same subsets
      const auto first = r.cases.size();
      training_and_cv(m, r.cases);
      out_of_gamut(m, r.cases);
      noise(m, rng, r.cases);
      exposure(m, r.cases);
      training_patches(m, rng, r.cases);
      other_lamps(m, r.cases);
      StabilityVerdict v{m};
      for (auto i = first; i < r.cases.size(); ++i) {
        judge(r.cases[i], o_);
        if (r.cases[i].fails && !v.fails) {
          v.fails = true;
          v.first_kind = r.cases[i].kind;
          v.first_level = r.cases[i].level;
          v.first_label = r.cases[i].label;
        }
      }
      r.verdicts.push_back(v);
    }
    return r;
  }

 private:
  void gamut_split(StabilityResult& r) {
    const std::size_t n = train_.size();
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), 0);
    auto chroma = [&](std::size_t i) {
      return std::hypot(train_.lab(static_cast<Eigen::Index>(i), 1), train_.lab(static_cast<Eigen::Index>(i), 2));
    };
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return chroma(a) > chroma(b); });
    const auto held = std::clamp<std::size_t>(static_cast<std::size_t>(std::lround(o_.gamut_fraction * static_cast<double>(n))), 1, n - 1);
    held_.assign(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(held));
    kept_.assign(order.begin() + static_cast<std::ptrdiff_t>(held), order.end());
    r.gamut_held_out = held;
    for (auto i : held_) r.gamut_ids.push_back(train_.ids[i]);
  }

  template <class Body>
  void guarded(StabilityCase c, std::vector<StabilityCase>& out, Body body) {
    try {
      body(c);
    } catch (const Error& e) {
      if (e.cls() != ErrorClass::bad_data) throw;
      c = not_fitted(std::move(c), e.what());
    }
    out.push_back(std::move(c));
  }

  void training_and_cv(const std::string& m, std::vector<StabilityCase>& out) {
    // One report: the training errors and the cross-validated ones of the same fit.
    FitReport rep;
    std::string why;
    try {
      rep = report_method(m, train_, o_.fit, o_.cv);
    } catch (const Error& e) {
      if (e.cls() != ErrorClass::bad_data) throw;
      why = e.what();
    }
    StabilityCase t{m, "training", double(train_.size())}, cv{m, "cross_validated", double(train_.size())};
    cv.label = o_.cv.name();
    if (!why.empty() || rep.rank_deficient) {
      if (why.empty()) why = m + ": rank-deficient on the training chart";
      out.push_back(not_fitted(t, why));
      out.push_back(not_fitted(cv, why));
      return;
    }
    set_patches(t, train_.ids, rep.training.de00);
    set_patches(cv, train_.ids, rep.cv.de00);
    out.push_back(std::move(t));
    out.push_back(std::move(cv));
  }

  void out_of_gamut(const std::string& m, std::vector<StabilityCase>& out) {
    guarded(StabilityCase{m, "out_of_gamut", double(held_.size())}, out, [&](StabilityCase& c) {
      const ChartData inside = train_.subset(kept_), outside = train_.subset(held_);
      const auto e = evaluate(fit_method(m, inside, o_.fit).apply(outside.rgb), outside.lab);
      set_patches(c, outside.ids, e.de00);
    });
  }

  void noise(const std::string& m, std::mt19937& rng, std::vector<StabilityCase>& out) {
    std::normal_distribution<double> z(0, 1);
    for (double sigma : o_.noise) {
      guarded(StabilityCase{m, "noise", sigma}, out, [&](StabilityCase& c) {
        std::vector<double> pooled;
        for (int d = 0; d < o_.draws; ++d) {
          ChartData noisy = train_;
          for (Eigen::Index i = 0; i < noisy.rgb.rows(); ++i)
            for (Eigen::Index j = 0; j < 3; ++j) noisy.rgb(i, j) *= 1 + sigma * z(rng);
          noisy.rgb = clipped(noisy.rgb, o_.saturation);
          const auto e = evaluate(fit_method(m, noisy, o_.fit).apply(test_.rgb), test_.lab);
          pooled.insert(pooled.end(), e.de00.begin(), e.de00.end());
        }
        set_pooled(c, pooled);
      });
    }
  }

  void exposure(const std::string& m, std::vector<StabilityCase>& out) {
    std::optional<Characterization> model;
    std::string why;
    try {
      model = fit_method(m, train_, o_.fit);
    } catch (const Error& e) {
      if (e.cls() != ErrorClass::bad_data) throw;
      why = e.what();
    }
    for (double k : o_.exposures) {
      StabilityCase c{m, "exposure", k};
      if (!model) {
        out.push_back(not_fitted(c, why));
        continue;
      }
      const auto e = evaluate(predict_at_exposure(*model, clipped(k * test_.rgb, o_.saturation), k, o_.fit, test_.white), test_.lab);
      set_patches(c, test_.ids, e.de00);
      out.push_back(std::move(c));
    }
  }

  void training_patches(const std::string& m, std::mt19937& rng, std::vector<StabilityCase>& out) {
    const std::size_t n = train_.size();
    std::vector<std::size_t> idx(n);
    for (std::size_t size : o_.training_sizes) {
      if (size >= n || size == 0) continue;  // the chart is no bigger; nothing would be left out
      guarded(StabilityCase{m, "training_patches", double(size)}, out, [&](StabilityCase& c) {
        std::vector<double> pooled;
        for (int d = 0; d < o_.draws; ++d) {
          std::iota(idx.begin(), idx.end(), 0);
          std::shuffle(idx.begin(), idx.end(), rng);
          const ChartData sub = train_.subset({idx.begin(), idx.begin() + static_cast<std::ptrdiff_t>(size)});
          const ChartData rest = independent_ ? test_ : train_.subset({idx.begin() + static_cast<std::ptrdiff_t>(size), idx.end()});
          const auto e = evaluate(fit_method(m, sub, o_.fit).apply(rest.rgb), rest.lab);
          pooled.insert(pooled.end(), e.de00.begin(), e.de00.end());
        }
        set_pooled(c, pooled);
      });
    }
  }

  void other_lamps(const std::string& m, std::vector<StabilityCase>& out) {
    for (const auto& [lamp, chart] : others_) {
      StabilityCase c{m, "other_lamp"};
      c.label = lamp;
      const auto rows = rows_by_id(chart, train_.ids);
      if (rows.empty()) throw Error(ErrorClass::bad_data, "stability: the chart under " + lamp + " shares no patch id with the training chart");
      const ChartData there = chart.subset(rows);
      c.level = double(there.size());
      guarded(c, out, [&](StabilityCase& cc) {
        const auto e = evaluate(fit_method(m, train_, o_.fit).apply(there.rgb), there.lab);
        set_patches(cc, there.ids, e.de00);
      });
    }
  }

  const ChartData& train_;
  const StabilityOptions& o_;
  const ChartData& test_;
  bool independent_;
  const std::vector<std::pair<std::string, ChartData>>& others_;
  std::vector<std::size_t> held_, kept_;
};

}  // namespace

StabilityResult run_stability(const ChartData& train, const StabilityOptions& options, const ChartData* test,
                              const std::vector<std::pair<std::string, ChartData>>& other_lamps) {
  check_options(options);
  train.check();
  if (train.size() < 3) throw Error(ErrorClass::bad_data, "stability: the training chart has fewer than 3 patches");
  if (test) test->check();
  for (const auto& [lamp, chart] : other_lamps) chart.check();
  return Suite(train, options, test, other_lamps).run();
}

}  // namespace colorlab::analysis
