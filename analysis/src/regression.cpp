#include "colorlab/analysis/regression.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "colorlab/analysis/color_difference.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Solution {
  Eigen::MatrixXd coefficients;  // m × 3 (for unscaled design columns)
  Eigen::VectorXd leverage;      // n
};

// Least squares by column-pivoting Householder QR on the column-equilibrated design: cond(X) instead of cond(X)².
Solution solve(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y, double ridge, const std::string& what,
               bool want_leverage) {
  const Eigen::Index n = X.rows(), m = X.cols();
  if (n < m)
    throw Error(ErrorClass::bad_data, what + ": " + std::to_string(n) + " patches cannot determine " +
                                          std::to_string(m) + " terms (rank-deficient design)");
  Eigen::VectorXd d = X.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < m; ++j)
    if (!(d(j) > 0))
      throw Error(ErrorClass::bad_data, what + ": term " + std::to_string(j + 1) + " is zero on every patch (rank-deficient design)");
  Eigen::MatrixXd A(ridge > 0 ? n + m : n, m), B = Eigen::MatrixXd::Zero(A.rows(), Y.cols());
  A.topRows(n) = X * d.cwiseInverse().asDiagonal();
  B.topRows(n) = Y;
  // The penalty acts on the coefficients of the 0..1-scaled terms, not of the equilibrated columns, so the model
  // does not depend on which patches set the column norms (and the LOO identity stays exact).
  if (ridge > 0) A.bottomRows(m) = std::sqrt(ridge) * Eigen::MatrixXd(d.cwiseInverse().asDiagonal());
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  qr.setThreshold(1e-12);
  if (qr.rank() < m)
    throw Error(ErrorClass::bad_data,
                what + ": design of " + std::to_string(n) + " patches x " + std::to_string(m) +
                    " terms has rank " + std::to_string(qr.rank()) + " (rank-deficient)",
                "use fewer terms, more (distinct) patches, or ridge");
  Solution s;
  s.coefficients = d.cwiseInverse().asDiagonal() * qr.solve(B);
  if (want_leverage) {
    Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(A.rows(), m);
    s.leverage = Q.topRows(n).rowwise().squaredNorm();
  }
  return s;
}

Eigen::MatrixXd target_of(const ChartData& d, FitTarget t) { return t == FitTarget::lab_direct ? d.lab : d.xyz; }

}  // namespace

Eigen::VectorXd target_weights(const ChartData& d, FitTarget t) {
  Eigen::VectorXd w = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(d.size()));
  if (t != FitTarget::xyz_lightness_weighted) return w;
  for (Eigen::Index i = 0; i < w.size(); ++i) {
    // Below L* ≈ 8 the CIE curve is linear, so the slope stops growing there.
    const double y = std::max(d.xyz(i, 1) / d.white.Y, 0.008856);
    w(i) = std::pow(y, -2.0 / 3.0);
  }
  return w;
}

namespace {
Eigen::VectorXd row_weights(const ChartData& d, FitTarget t) { return target_weights(d, t); }

double scale_for(const ChartData& d, const FitOptions& o) {
  if (o.input_scale > 0) return o.input_scale;
  double mx = d.rgb.maxCoeff();
  return mx > 0 ? mx : 1.0;
}

Summary summarize_with_inf(const std::vector<double>& v) {
  bool all_finite = std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
  if (all_finite) return summarize(v);
  std::vector<double> fin;
  for (double x : v)
    if (std::isfinite(x)) fin.push_back(x);
  Summary s = fin.empty() ? Summary{} : summarize(fin);
  s.count = v.size();
  s.max = s.mean = s.stdev = kInf;
  return s;
}
}  // namespace

void ChartData::check() const {
  const auto n = static_cast<Eigen::Index>(ids.size());
  if (n == 0) throw Error(ErrorClass::bad_data, "chart data has no patches");
  auto chk = [&](const Eigen::MatrixXd& m, const char* what) {
    if (m.rows() != n || m.cols() != 3)
      throw Error(ErrorClass::bad_data, std::string("chart ") + what + " has " + std::to_string(m.rows()) + "x" +
                                            std::to_string(m.cols()) + " values for " + std::to_string(n) + " patches");
    for (Eigen::Index i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(m(i, c)))
          throw Error(ErrorClass::bad_data, std::string("chart ") + what + " of patch " + ids[static_cast<std::size_t>(i)] +
                                                " is not finite");
  };
  chk(rgb, "RGB");
  chk(xyz, "XYZ");
  chk(lab, "L*a*b*");
}

ChartData ChartData::subset(const std::vector<std::size_t>& rows) const {
  ChartData s;
  s.white = white;
  const auto k = static_cast<Eigen::Index>(rows.size());
  s.rgb.resize(k, 3);
  s.xyz.resize(k, 3);
  s.lab.resize(k, 3);
  for (Eigen::Index i = 0; i < k; ++i) {
    auto r = static_cast<Eigen::Index>(rows[static_cast<std::size_t>(i)]);
    if (r >= static_cast<Eigen::Index>(size())) throw Error(ErrorClass::bad_parameter, "patch index out of range");
    s.ids.push_back(ids[static_cast<std::size_t>(r)]);
    s.rgb.row(i) = rgb.row(r);
    s.xyz.row(i) = xyz.row(r);
    s.lab.row(i) = lab.row(r);
  }
  return s;
}

const char* to_string(FitTarget t) {
  switch (t) {
    case FitTarget::lab_direct: return "lab";
    case FitTarget::xyz_then_lab: return "xyz";
    case FitTarget::xyz_lightness_weighted: return "xyzw";
  }
  return "?";
}

Eigen::MatrixXd xyz_rows_to_lab(const Eigen::MatrixXd& xyz, const Xyz& white) {
  Eigen::MatrixXd lab(xyz.rows(), 3);
  for (Eigen::Index i = 0; i < xyz.rows(); ++i) {
    Lab l = xyz_to_lab({xyz(i, 0), xyz(i, 1), xyz(i, 2)}, white);
    lab.row(i) << l.L, l.a, l.b;
  }
  return lab;
}

PolynomialModel::PolynomialModel(TermSet terms, FitTarget target, Eigen::MatrixXd coefficients, double input_scale,
                                 Xyz white)
    : terms_(std::move(terms)), target_(target), coefficients_(std::move(coefficients)), input_scale_(input_scale),
      white_(white) {}

Eigen::MatrixXd PolynomialModel::predict_target(const Eigen::MatrixXd& rgb) const {
  return expand_terms(terms_, rgb / input_scale_) * coefficients_;
}

Eigen::MatrixXd PolynomialModel::apply(const Eigen::MatrixXd& rgb) const {
  Eigen::MatrixXd t = predict_target(rgb);
  return target_ == FitTarget::lab_direct ? t : xyz_rows_to_lab(t, white_);
}

PolynomialModel fit(const TermSet& terms, const ChartData& train, const FitOptions& o) {
  train.check();
  const double scale = scale_for(train, o);
  const Eigen::VectorXd w = row_weights(train, o.target);
  Eigen::MatrixXd X = w.asDiagonal() * expand_terms(terms, train.rgb / scale);
  auto s = solve(X, w.asDiagonal() * target_of(train, o.target), o.ridge, terms.name, false);
  return PolynomialModel(terms, o.target, s.coefficients, scale, train.white);
}

PolynomialModel fit(const std::string& method, const ChartData& train, const FitOptions& o) {
  return fit(term_set_by_name(method), train, o);
}

ErrorStats evaluate(const Eigen::MatrixXd& pred, const Eigen::MatrixXd& ref) {
  if (pred.rows() != ref.rows() || pred.cols() != 3 || ref.cols() != 3)
    throw Error(ErrorClass::bad_data, "prediction has " + std::to_string(pred.rows()) + " rows, reference " +
                                          std::to_string(ref.rows()));
  if (pred.rows() == 0) throw Error(ErrorClass::bad_data, "no patches to evaluate");
  ErrorStats e;
  for (Eigen::Index i = 0; i < pred.rows(); ++i) {
    Lab p{pred(i, 0), pred(i, 1), pred(i, 2)}, r{ref(i, 0), ref(i, 1), ref(i, 2)};
    bool ok = std::isfinite(p.L) && std::isfinite(p.a) && std::isfinite(p.b);
    e.de76.push_back(ok ? delta_e76(p, r) : kInf);
    e.de00.push_back(ok ? delta_e2000(r, p) : kInf);
  }
  e.s76 = summarize_with_inf(e.de76);
  e.s00 = summarize_with_inf(e.de00);
  return e;
}

CvSpec CvSpec::parse(const std::string& t) {
  if (t == "loo") return loo();
  if (t == "none") return {Kind::none, 0, 1};
  if (t.size() > 1 && t[0] == 'k') {
    try {
      std::size_t used = 0;
      int k = std::stoi(t.substr(1), &used);
      if (used == t.size() - 1 && k >= 2) return k_fold(k);
    } catch (const std::exception&) {
    }
  }
  throw Error(ErrorClass::bad_parameter, "cross-validation '" + t + "' is not loo, none or kN (N >= 2)");
}

std::string CvSpec::name() const {
  switch (kind) {
    case Kind::none: return "none";
    case Kind::leave_one_out: return "loo";
    case Kind::k_fold: return "k" + std::to_string(folds);
  }
  return "?";
}

ErrorStats cross_validate(const TermSet& terms, const ChartData& data, const FitOptions& o, const CvSpec& cv) {
  data.check();
  const auto n = static_cast<Eigen::Index>(data.size());
  const double scale = scale_for(data, o);
  Eigen::MatrixXd pred = Eigen::MatrixXd::Constant(n, 3, std::numeric_limits<double>::quiet_NaN());
  const Eigen::MatrixXd Y = target_of(data, o.target);
  if (cv.kind == CvSpec::Kind::none) {
    pred = fit(terms, data, o).predict_target(data.rgb);
  } else if (cv.kind == CvSpec::Kind::leave_one_out) {
    const Eigen::VectorXd w = row_weights(data, o.target);
    Eigen::MatrixXd X = w.asDiagonal() * expand_terms(terms, data.rgb / scale);
    try {
      const Eigen::MatrixXd Yw = w.asDiagonal() * Y;
      auto s = solve(X, Yw, o.ridge, terms.name, true);
      // Weighted residuals over (1 − h_ii) are the weighted held-out residuals; unweight them.
      Eigen::MatrixXd resid = (Yw - X * s.coefficients).array().colwise() / w.array();
      // PRESS identity: the held-out residual is e_i / (1 − h_ii), exact for least squares and ridge alike.
      for (Eigen::Index i = 0; i < n; ++i) {
        double denom = 1 - s.leverage(i);
        if (denom > 1e-10) pred.row(i) = Y.row(i) - resid.row(i) / denom;
      }
    } catch (const Error&) {
      // Rank-deficient on all patches: every held-out prediction is undefined (left NaN → infinite error).
    }
  } else {
    if (cv.folds < 2 || cv.folds > n)
      throw Error(ErrorClass::bad_parameter, std::to_string(cv.folds) + "-fold cross-validation on " +
                                                 std::to_string(n) + " patches");
    std::vector<std::size_t> order(static_cast<std::size_t>(n));
    std::iota(order.begin(), order.end(), 0);
    std::mt19937 rng(cv.seed);
    std::shuffle(order.begin(), order.end(), rng);
    FitOptions fo = o;
    fo.input_scale = scale;
    for (int f = 0; f < cv.folds; ++f) {
      std::vector<std::size_t> train, test;
      for (std::size_t i = 0; i < order.size(); ++i)
        (static_cast<int>(i % static_cast<std::size_t>(cv.folds)) == f ? test : train).push_back(order[i]);
      try {
        auto model = fit(terms, data.subset(train), fo);
        ChartData t = data.subset(test);
        Eigen::MatrixXd p = model.predict_target(t.rgb);
        for (std::size_t i = 0; i < test.size(); ++i) pred.row(static_cast<Eigen::Index>(test[i])) = p.row(static_cast<Eigen::Index>(i));
      } catch (const Error&) {
        // This fold's training subset is rank-deficient: its patches stay unpredicted.
      }
    }
  }
  Eigen::MatrixXd lab = o.target == FitTarget::lab_direct ? pred : xyz_rows_to_lab(pred, data.white);
  return evaluate(lab, data.lab);
}

FitReport fit_report(const TermSet& terms, const ChartData& data, const FitOptions& o, const CvSpec& cv) {
  FitReport r;
  r.method = terms.name;
  r.terms = terms.size();
  r.parameters = static_cast<double>(terms.size());
  r.target = o.target;
  r.cv_name = cv.name();
  try {
    auto model = fit(terms, data, o);
    r.training = evaluate(model.apply(data.rgb), data.lab);
  } catch (const Error&) {
    r.rank_deficient = true;
    std::vector<double> inf(data.size(), kInf);
    r.training = {inf, inf, summarize_with_inf(inf), summarize_with_inf(inf)};
  }
  r.cv = cross_validate(terms, data, o, cv);
  return r;
}

void choose_smallest_within_tolerance(Selection& s, const SelectionOptions& so, std::size_t patches) {
  if (s.candidates.empty()) throw Error(ErrorClass::bad_parameter, "no candidate models to select from");
  s.tolerance = so.tolerance_de00;
  s.best = s.chosen = 0;
  auto mean = [&](std::size_t i) { return s.candidates[i].cv.s00.mean; };
  for (std::size_t i = 1; i < s.candidates.size(); ++i)
    if (mean(i) < mean(s.best)) s.best = i;
  if (!std::isfinite(mean(s.best)))
    throw Error(ErrorClass::bad_data, "no candidate model could be cross-validated on " + std::to_string(patches) + " patches");
  bool found = false;
  for (std::size_t i = 0; i < s.candidates.size(); ++i) {
    if (!(mean(i) <= mean(s.best) + so.tolerance_de00)) continue;
    const double pi = s.candidates[i].parameters, pc = s.candidates[s.chosen].parameters;
    if (!found || pi < pc || (pi == pc && mean(i) < mean(s.chosen))) {
      s.chosen = i;
      found = true;
    }
  }
}

Selection select_model(const std::vector<TermSet>& sets, const std::vector<FitTarget>& targets, const ChartData& data,
                       const FitOptions& o, const CvSpec& cv, const SelectionOptions& so) {
  if (sets.empty() || targets.empty()) throw Error(ErrorClass::bad_parameter, "no candidate models to select from");
  if (cv.kind == CvSpec::Kind::none)
    throw Error(ErrorClass::bad_parameter, "model selection needs cross-validation, not training error");
  Selection s;
  s.tolerance = so.tolerance_de00;
  for (const auto& t : targets)
    for (const auto& set : sets) {
      FitOptions fo = o;
      fo.target = t;
      s.candidates.push_back(fit_report(set, data, fo, cv));
    }
  choose_smallest_within_tolerance(s, so, data.size());
  return s;
}

}  // namespace colorlab::analysis
