#include "colorlab/cli/analyze_command.hpp"

#include <array>
#include <iostream>
#include <memory>
#include <optional>

#include "analyze_output.hpp"
#include "colorlab/analysis/blackbox.hpp"
#include "colorlab/analysis/characterization.hpp"
#include "colorlab/analysis/chart_io.hpp"
#include "colorlab/analysis/color_difference.hpp"
#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/csv.hpp"
#include "colorlab/analysis/frame_accumulator.hpp"
#include "colorlab/analysis/patch_stats.hpp"
#include "colorlab/analysis/regression.hpp"
#include "colorlab/analysis/uniformity.hpp"
#include "colorlab/core/error.hpp"
#include "locate_chart_command.hpp"
#include "pgm_reader.hpp"
#include "stability_command.hpp"

namespace colorlab::cli {

namespace ca = colorlab::analysis;
using detail::Table;

namespace {

using Row = std::vector<detail::Cell>;

Row summary_row(const std::string& name, const ca::Summary& s) { return {name, s.min, s.max, s.median, s.mean, s.stdev}; }
const std::vector<std::string> kSummaryColumns{"quantity", "min", "max", "median", "mean", "stdev"};

struct SpectraOptions {
  std::string file, illuminant = "D50";
  int observer = 2;
  bool json = false;
};

void run_spectra(const SpectraOptions& o, bool lab) {
  ca::SpectralSet s = ca::read_spectra(o.file);
  ca::ReflectanceIntegrator integ(ca::load_illuminant(o.illuminant), ca::load_observer(ca::observer_from_degrees(o.observer)),
                                  s.wavelengths);
  auto xyz = integ.xyz(s);
  Table t{lab ? "lab" : "xyz", {}, {}};
  t.columns = lab ? std::vector<std::string>{"id", "L", "a", "b"} : std::vector<std::string>{"id", "X", "Y", "Z", "x", "y"};
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    if (lab) {
      auto l = ca::xyz_to_lab(xyz[i], integ.white());
      t.rows.push_back({s.names[i], l.L, l.a, l.b});
    } else {
      auto c = ca::xyz_to_xyy(xyz[i]);
      t.rows.push_back({s.names[i], xyz[i].X, xyz[i].Y, xyz[i].Z, c.x, c.y});
    }
  }
  const auto w = integ.white();
  Table white{"white", {"illuminant", "observer", "X", "Y", "Z"}, {{o.illuminant, double(o.observer), w.X, w.Y, w.Z}}};
  detail::print_tables(std::cout, {t, white}, o.json);
}

struct De2000Options {
  std::string file;
  bool json = false;
};

void run_de2000(const De2000Options& o) {
  ca::CsvTable t = ca::read_csv(o.file);
  const auto L1 = t.require_column("L1"), a1 = t.require_column("a1"), b1 = t.require_column("b1"),
             L2 = t.require_column("L2"), a2 = t.require_column("a2"), b2 = t.require_column("b2");
  Table out{"pairs", {"pair", "dE00", "dE76"}, {}};
  std::vector<double> d00, d76;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    ca::Lab p{t.number(r, L1), t.number(r, a1), t.number(r, b1)}, q{t.number(r, L2), t.number(r, a2), t.number(r, b2)};
    d00.push_back(ca::delta_e2000(p, q));
    d76.push_back(ca::delta_e76(p, q));
    out.rows.push_back({t.rows[r][0], d00.back(), d76.back()});
  }
  Table sum{"summary", kSummaryColumns, {summary_row("dE00", ca::summarize(d00)), summary_row("dE76", ca::summarize(d76))}};
  detail::print_tables(std::cout, {out, sum}, o.json);
}

struct FitCliOptions {
  std::string method = "auto", train, test, cv = "loo", target = "xyz", spectra, illuminant = "D65", basis;
  std::vector<std::string> exclude_cameras;
  double ridge = 0, tolerance = 0.1, full_scale = 4095, input_scale = 0;
  bool json = false;
};

ca::FitTarget parse_target(const std::string& t) {
  if (t == "xyz") return ca::FitTarget::xyz_then_lab;
  if (t == "xyzw") return ca::FitTarget::xyz_lightness_weighted;
  if (t == "lab") return ca::FitTarget::lab_direct;
  throw Error(ErrorClass::bad_parameter, "--target must be xyz, xyzw or lab, not '" + t + "'");
}

// Camera-curve collections rarely span a chart's whole spectral range (camspec: 400–720 nm); the fit then uses the
// bands both share, and says so.
ca::SpectralSet crop_to_range(const ca::SpectralSet& s, double from_nm, double to_nm) {
  std::vector<std::size_t> keep;
  for (std::size_t k = 0; k < s.bands(); ++k)
    if (s.wavelengths[k] >= from_nm - 1e-9 && s.wavelengths[k] <= to_nm + 1e-9) keep.push_back(k);
  if (keep.size() == s.bands()) return s;
  if (keep.size() < 3)
    throw Error(ErrorClass::bad_data, "blackbox: spectra in " + s.source + " and the --basis curves share fewer than 3 wavelengths");
  ca::SpectralSet out = s;
  out.wavelengths.clear();
  out.values.resize(s.values.rows(), static_cast<Eigen::Index>(keep.size()));
  for (std::size_t j = 0; j < keep.size(); ++j) {
    out.wavelengths.push_back(s.wavelengths[keep[j]]);
    out.values.col(static_cast<Eigen::Index>(j)) = s.values.col(static_cast<Eigen::Index>(keep[j]));
  }
  std::cerr << "blackbox: fitting " << out.wavelengths.front() << "–" << out.wavelengths.back() << " nm, the range of the --basis curves\n";
  return out;
}

void run_blackbox(const FitCliOptions& o) {
  if (o.spectra.empty()) throw Error(ErrorClass::bad_parameter, "--method blackbox needs --spectra (one spectrum per patch)");
  ca::CsvTable raw_t = ca::read_csv(o.train);
  ca::SpectralSet spectra = ca::read_spectra(o.spectra);
  std::optional<ca::SpectralSet> basis;
  if (!o.basis.empty()) {
    basis = ca::read_spectra(o.basis);
    spectra = crop_to_range(spectra, basis->wavelengths.front(), basis->wavelengths.back());
  }
  const auto id = raw_t.require_column(raw_t.header[0]), R = raw_t.require_column("R"), G = raw_t.require_column("G"),
             B = raw_t.require_column("B");
  // Reflectances (≤ 1.5) are lit by the illuminant; anything brighter is taken as radiance already.
  const bool reflectance = spectra.values.maxCoeff() <= 1.5;
  Eigen::RowVectorXd lamp = Eigen::RowVectorXd::Ones(static_cast<Eigen::Index>(spectra.bands()));
  if (reflectance) lamp = ca::resample(ca::load_illuminant(o.illuminant), spectra.wavelengths, ca::Interpolation::linear).values.row(0);
  Eigen::MatrixXd X(static_cast<Eigen::Index>(raw_t.rows.size()), static_cast<Eigen::Index>(spectra.bands())), Y(X.rows(), 3);
  for (std::size_t r = 0; r < raw_t.rows.size(); ++r) {
    auto k = static_cast<Eigen::Index>(spectra.require(raw_t.rows[r][id]));
    X.row(static_cast<Eigen::Index>(r)) = spectra.values.row(k).cwiseProduct(lamp);
    Y.row(static_cast<Eigen::Index>(r)) << raw_t.number(r, R), raw_t.number(r, G), raw_t.number(r, B);
  }
  ca::BlackBoxOptions bo;
  bo.full_scale = o.full_scale;
  if (basis) bo.prior = ca::learn_sensitivity_prior(*basis, spectra.wavelengths, o.exclude_cameras);
  else if (!o.exclude_cameras.empty()) throw Error(ErrorClass::bad_parameter, "--exclude-camera needs --basis");
  auto model = ca::fit_blackbox(X, Y, bo);
  auto res = ca::blackbox_residuals(model, X, Y, o.full_scale);
  Table t13{"residuals", {"channel", "min", "max", "median", "mean", "stdev", "min_pct", "max_pct", "median_pct", "mean_pct", "stdev_pct"}, {}};
  for (int c = 0; c < 3; ++c) {
    const auto& a = res.counts[static_cast<std::size_t>(c)];
    const auto& p = res.percent[static_cast<std::size_t>(c)];
    t13.rows.push_back({std::string(1, "RGB"[c]), a.min, a.max, a.median, a.mean, a.stdev, p.min, p.max, p.median, p.mean, p.stdev});
  }
  // With a prior each curve carries its 95 % credible band (docs/ACCURACY.md: how often it holds the truth).
  Table curves{"sensitivities", {"wavelength_nm", "R", "G", "B"}, {}};
  std::array<ca::CurveBand, 3> bands;
  if (model.with_prior) {
    for (const char* col : {"R_low", "R_high", "G_low", "G_high", "B_low", "B_high"}) curves.columns.push_back(col);
    for (int c = 0; c < 3; ++c)
      bands[static_cast<std::size_t>(c)] = ca::credible_band(model.sensitivities.row(c).transpose(), model.sensitivity_sdev.row(c).transpose());
  }
  for (std::size_t k = 0; k < spectra.bands(); ++k) {
    auto kk = static_cast<Eigen::Index>(k);
    curves.rows.push_back({spectra.wavelengths[k], model.sensitivities(0, kk), model.sensitivities(1, kk), model.sensitivities(2, kk)});
    if (model.with_prior)
      for (const auto& b : bands) {
        curves.rows.back().push_back(b.lower(kk));
        curves.rows.back().push_back(b.upper(kk));
      }
  }
  detail::print_tables(std::cout, {t13, curves}, o.json);
}

void add_report_rows(Table& t, const ca::FitReport& r, const std::string& cv) {
  t.rows.push_back({r.method, double(r.terms), ca::to_string(r.target), r.training.s76.mean, r.training.s00.mean,
                    r.training.s00.max, r.cv.s76.mean, r.cv.s00.mean, r.cv.s00.max, cv, r.parameters});
}

void run_fit(const FitCliOptions& o) {
  if (o.method == "blackbox") return run_blackbox(o);
  ca::ChartData train = ca::read_chart(o.train);
  ca::FitOptions fo;
  fo.ridge = o.ridge;
  fo.input_scale = o.input_scale;
  fo.target = parse_target(o.target);
  const ca::CvSpec cv = ca::CvSpec::parse(o.cv);
  Table fits{"fits", {
                         "method",
                         "terms",
                         "target",
                         "train_dE76_mean",
                         "train_dE00_mean",
                         "train_dE00_max",
                         "cv_dE76_mean",
                         "cv_dE00_mean",
                         "cv_dE00_max",
                         "cv",
                         "parameters",
                     },
             {}};
  // Splines (rbf:<term set>) are candidates of `auto` beside every polynomial; selection compares effective parameters.
  std::string chosen = o.method;
  if (o.method == "auto") {
    ca::SelectionOptions so;
    so.tolerance_de00 = o.tolerance;
    auto sel = ca::select_method(ca::all_methods(), {fo.target}, train, fo, cv, so);
    for (const auto& r : sel.candidates) add_report_rows(fits, r, cv.name());
    chosen = sel.candidates[sel.chosen].method;
  } else {
    add_report_rows(fits, ca::report_method(o.method, train, fo, cv), cv.name());
  }
  const auto model = ca::fit_method(chosen, train, fo);
  const double terms = model.spline() ? double(model.spline()->base_terms()) : double(ca::term_set_by_name(chosen).size());
  Table model_t{
      "model",
      {"method", "terms", "target", "input_scale", "description"},
      {{chosen, terms, ca::to_string(fo.target), model.input_scale(), model.describe()}},
  };
  std::vector<Table> out{fits, model_t};
  if (!o.test.empty()) {
    ca::ChartData test = ca::read_chart(o.test);
    auto lab = model.apply(test.rgb);
    auto e = ca::evaluate(lab, test.lab);
    Table per{"test_patches", {"id", "L", "a", "b", "L_ref", "a_ref", "b_ref", "dE76", "dE00"}, {}};
    for (std::size_t i = 0; i < test.size(); ++i) {
      auto r = static_cast<Eigen::Index>(i);
      per.rows.push_back({test.ids[i], lab(r, 0), lab(r, 1), lab(r, 2), test.lab(r, 0), test.lab(r, 1), test.lab(r, 2), e.de76[i], e.de00[i]});
    }
    out.push_back(per);
    out.push_back(Table{"test_summary", kSummaryColumns, {summary_row("dE76", e.s76), summary_row("dE00", e.s00)}});
  }
  detail::print_tables(std::cout, out, o.json);
}

Eigen::MatrixXd read_grid(const std::string& file) {
  const ca::CsvTable t = ca::read_csv(file, {.header = false});
  // A first row that is not all numbers names the columns.
  std::size_t first = 0;
  if (!t.rows.empty()) {
    for (std::size_t c = 0; c < t.columns(); ++c)
      if (!t.try_number(0, c)) first = 1;
  }
  if (t.rows.size() <= first) throw Error(ErrorClass::bad_data, file + ": no luminance rows");
  Eigen::MatrixXd g(static_cast<Eigen::Index>(t.rows.size() - first), static_cast<Eigen::Index>(t.columns()));
  for (std::size_t i = first; i < t.rows.size(); ++i)
    for (std::size_t j = 0; j < t.columns(); ++j) g(static_cast<Eigen::Index>(i - first), static_cast<Eigen::Index>(j)) = t.number(i, j);
  return g;
}

struct UniformityCliOptions {
  std::string file, full;
  double setting = 0;
  bool json = false;
};

void run_uniformity(const UniformityCliOptions& o) {
  auto res = ca::analyse_uniformity(read_grid(o.file));
  Table windows{"window_stdev", {"i"}, {}};
  for (Eigen::Index j = 0; j < res.window_stdev.cols(); ++j) windows.columns.push_back(std::to_string(j));
  for (Eigen::Index i = 0; i < res.window_stdev.rows(); ++i) {
    Row r{std::to_string(i)};
    for (Eigen::Index j = 0; j < res.window_stdev.cols(); ++j) r.push_back(res.window_stdev(i, j));
    windows.rows.push_back(std::move(r));
  }
  Table best{
      "placement",
      {"min", "max", "range", "best_row", "best_col", "best_stdev"},
      {{res.min, res.max, res.max - res.min, double(res.best.row), double(res.best.col), res.best.stdev}},
  };
  std::vector<Table> out{windows, best};
  if (!o.full.empty()) {
    if (!(o.setting > 0)) throw Error(ErrorClass::bad_parameter, "--full needs --setting (e.g. 0.5 for 50 %)");
    auto full = ca::analyse_uniformity(read_grid(o.full));
    auto d = ca::dimmer_proportionality(full.difference, res.difference, o.setting);
    out.push_back(Table{"dimmer", {"setting", "max_abs_error"}, {{o.setting, d.max_abs_error}}});
  }
  detail::print_tables(std::cout, out, o.json);
}

struct AveragingOptions {
  std::vector<std::string> frames;
  std::string regions;
  int bits = 0;
  bool json = false;
};

void run_averaging(const AveragingOptions& o) {
  if (o.frames.empty()) throw Error(ErrorClass::bad_parameter, "no frames given");
  std::vector<detail::GrayFrame> frames;
  std::unique_ptr<ca::FrameAccumulator> acc;
  for (const auto& f : o.frames) {
    frames.push_back(detail::read_pgm(f));
    const auto& g = frames.back();
    if (!acc) acc = std::make_unique<ca::FrameAccumulator>(g.width, g.height);
    if (g.width != acc->width() || g.height != acc->height())
      throw Error(ErrorClass::bad_data, f + ": frame size differs from the first frame");
    acc->add(g.pixels);
  }
  auto sd = acc->stddev();
  std::vector<double> sdd(sd.begin(), sd.end());
  std::vector<Table> out{Table{"pixel_stdev", kSummaryColumns, {summary_row("stdev over " + std::to_string(acc->frames()) + " frames", ca::summarize(sdd))}}};
  if (!o.regions.empty()) {
    ca::CsvTable rt = ca::read_csv(o.regions);
    const auto x = rt.require_column("x"), y = rt.require_column("y"), w = rt.require_column("width"), h = rt.require_column("height");
    std::vector<ca::Rect> rects;
    for (std::size_t r = 0; r < rt.rows.size(); ++r)
      rects.push_back({static_cast<std::size_t>(rt.number(r, x)), static_cast<std::size_t>(rt.number(r, y)),
                       static_cast<std::size_t>(rt.number(r, w)), static_cast<std::size_t>(rt.number(r, h))});
    std::vector<std::vector<float>> fl;
    std::vector<ca::ImageView> views;
    for (const auto& g : frames) fl.emplace_back(g.pixels.begin(), g.pixels.end());
    for (const auto& f : fl) views.push_back({f.data(), frames[0].width, frames[0].height, frames[0].width});
    std::vector<std::size_t> subsets;
    for (std::size_t n : ca::kTable2Subsets)
      if (n <= views.size()) subsets.push_back(n);
    auto rows = ca::noise_vs_averaging(views, rects, subsets);
    Table t2{"noise_vs_frames", {"frames", "median_stdev", "mean_stdev", "min", "max"}, {}};
    for (const auto& r : rows) t2.rows.push_back({double(r.frames), r.summary.median, r.summary.mean, r.summary.min, r.summary.max});
    out.push_back(t2);
    // Patch values of the averaged frame with the dissertation's robust estimator.
    auto mean = acc->mean();
    ca::ImageView mv{mean.data(), acc->width(), acc->height(), acc->width()};
    ca::RobustOptions ro;
    ro.bit_depth = o.bits > 0 ? o.bits : (frames[0].maxval > 255 ? 16 : 8);
    Table pv{"patch_values", {"region", "value", "median", "used", "total"}, {}};
    for (std::size_t i = 0; i < rects.size(); ++i) {
      auto v = ca::robust_patch_value(mv, rects[i], ro);
      pv.rows.push_back({std::to_string(i + 1), v.value, v.median, double(v.used), double(v.total)});
    }
    out.push_back(pv);
  }
  detail::print_tables(std::cout, out, o.json);
}

}  // namespace

void add_analyze_command(CLI::App& app) {
  auto* analyze = app.add_subcommand("analyze", "Colour science over files: spectra to XYZ/L*a*b*, colour differences, "
                                                "camera characterization and its stability, cabinet uniformity, frame averaging");
  analyze->require_subcommand(1);

  for (bool lab : {false, true}) {
    auto o = std::make_shared<SpectraOptions>();
    auto* c = analyze->add_subcommand(lab ? "lab" : "xyz",
                                      lab ? "Reflectance spectra to CIE L*a*b* (white = the illuminant's)"
                                          : "Reflectance spectra to CIE XYZ (Y = 100 for the perfect reflector) and xy");
    c->add_option("SPECTRA", o->file, "CGATS (.sp/.ti3/.cie) or CSV (wavelength_nm, one column per sample)")->required();
    c->add_option("--illuminant", o->illuminant, "CIE illuminant from colord-data: A, D50, D65, F2, F11, ...")->capture_default_str();
    c->add_option("--observer", o->observer, "Standard observer in degrees")->check(CLI::IsMember({2, 10}))->capture_default_str();
    c->add_flag("--json", o->json, "JSON instead of CSV");
    c->callback([o, lab] { run_spectra(*o, lab); });
  }
  {
    auto o = std::make_shared<De2000Options>();
    auto* c = analyze->add_subcommand("de2000", "CIEDE2000 (and ΔE*ab) for pairs: CSV with columns L1,a1,b1,L2,a2,b2");
    c->add_option("PAIRS", o->file, "CSV file; the first column names the pair")->required();
    c->add_flag("--json", o->json, "JSON instead of CSV");
    c->callback([o] { run_de2000(*o); });
  }
  {
    auto o = std::make_shared<FitCliOptions>();
    auto* c = analyze->add_subcommand("fit", "Fit a camera characterization with cross-validated errors beside training errors");
    c->add_option("--method", o->method,
                  "poly:1..11 (dissertation §7.3), hong:N (3,5,7,8,10,11,14,16,17,19,20), rootpoly:1..4, ccm, "
                  "rbf:<any of those> (r³ spline over that base, smoothing by LOO), "
                  "auto (every family: smallest model within --tolerance of the best CV error), blackbox (§7.4, needs --spectra)")
        ->capture_default_str();
    c->add_option("--train", o->train, "Training chart: CSV (id,R,G,B,X,Y,Z and/or L,a,b) or Argyll .ti3; blackbox: id,R,G,B RAW")->required();
    c->add_option("--test", o->test, "Independent test chart (same format)");
    c->add_option("--cv", o->cv, "Cross-validation: loo, kN (e.g. k5) or none")->capture_default_str();
    c->add_option("--target", o->target, "xyz (fit XYZ, then L*a*b*), xyzw (lightness-weighted XYZ) or lab (direct)")->capture_default_str();
    c->add_option("--ridge", o->ridge, "Ridge (Tikhonov) weight on the 0..1-scaled term coefficients")->capture_default_str();
    c->add_option("--input-scale", o->input_scale, "Divide RGB by this (0 = largest training value)")->capture_default_str();
    c->add_option("--tolerance", o->tolerance, "auto: accepted mean CV ΔE00 above the best model")->capture_default_str();
    c->add_option("--spectra", o->spectra, "blackbox: spectra per patch (reflectance is lit by --illuminant)");
    c->add_option("--illuminant", o->illuminant, "blackbox: illuminant for reflectance spectra")->capture_default_str();
    c->add_option("--full-scale", o->full_scale, "blackbox: RAW full scale for % residuals")->capture_default_str();
    c->add_option("--basis", o->basis,
                  "blackbox: measured curves of other cameras (CSV/CGATS, columns <camera>_R/_G/_B); fits under their "
                  "statistical prior instead of the second-difference penalty");
    c->add_option("--exclude-camera", o->exclude_cameras, "blackbox: leave this camera of --basis out (repeatable)");
    c->add_flag("--json", o->json, "JSON instead of CSV");
    c->callback([o] { run_fit(*o); });
  }
  {
    auto o = std::make_shared<UniformityCliOptions>();
    auto* c = analyze->add_subcommand("uniformity", "Light-cabinet uniformity (§6.2): left-half spot grid (8x10 CSV of cd/m²) "
                                                    "mirrored to 8x20, std of every 4x5 window, best chart placement");
    c->add_option("GRID", o->file, "CSV of luminances, one cabinet row per line (optional header)")->required();
    c->add_option("--full", o->full, "Grid at 100 % to check dimmer proportionality against");
    c->add_option("--setting", o->setting, "Dimmer setting of GRID as a fraction (e.g. 0.5)");
    c->add_flag("--json", o->json, "JSON instead of CSV");
    c->callback([o] { run_uniformity(*o); });
  }
  {
    auto o = std::make_shared<AveragingOptions>();
    auto* c = analyze->add_subcommand("averaging", "Per-pixel mean/std over frames (streamed) and Table 2 noise vs number of "
                                                   "frames averaged (1, 2, 4, 8, 16, 25)");
    c->add_option("FRAMES", o->frames, "Binary PGM frames (P5, 8 or 16 bit), e.g. dcraw -4 -D output")->required();
    c->add_option("--regions", o->regions, "CSV x,y,width,height of patch regions for Table 2 and robust patch values");
    c->add_option("--bits", o->bits, "Bit depth for the robust band k = 5·2^(bits−8) (default from the PGM maxval)");
    c->add_flag("--json", o->json, "JSON instead of CSV");
    c->callback([o] { run_averaging(*o); });
  }
  detail::add_locate_chart_command(*analyze);
  detail::add_stability_command(*analyze);
}

}  // namespace colorlab::cli
