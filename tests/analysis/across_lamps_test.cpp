// Issue 26: a characterization carried across a lamp change through the camera's estimated sensitivities, against an
// independent truth. The issue's fairness rules: the camera is left out of the sensitivity prior; the sensitivities
// are estimated from a noisy photograph under the training lamp (SG × D65, 0.5 % multiplicative RAW noise); the test
// chart (CC24, a different chart) is photographed under a MEASURED booth lamp (Gretag booth A and CWF, ../shared/data)
// while the model assumes the CIE standard it is named after (A, F2). The truth is rendered here, on the booth file's
// own 5 nm grid (the model integrates at 1 nm), with CIE 1931 XYZ Bradford-adapted to the ICC D50 white.
//
// What is asserted and why (bounds from the issue, never from a run):
// - the across-lamps model beats the same-lamp selection applied across lamps (today's path) on mean and maximum
//   ΔE00 in every case — the honest claim; the issue's Argyll targets (max below `colprof -ax` in ≥ 16/18, mean in
//   18/18) are measured by bench_analysis_across_lamps, which runs colprof (docs/ACCURACY.md §6);
// - the per-patch 95 % band holds the truth at ≥ 80 % of patches in every case (the issue's per-case bound) and at
//   90–98 % pooled (the issue's calibration target) — see the comment at that assertion for what was measured;
// - a nominal lamp is warned about, a measured one is not; bad lamps are typed errors.
#include <gtest/gtest.h>

#include <random>

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/relighting.hpp"
#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/core/error.hpp"
#include "test_support.hpp"

namespace ca = colorlab::analysis;

namespace {

const std::vector<ca::FitTarget> kTargets = {ca::FitTarget::xyz_then_lab, ca::FitTarget::xyz_lightness_weighted, ca::FitTarget::lab_direct};

// White-balanced camera RGB and reference L*a*b* of a chart under a lamp, on the lamp's own grid (5 nm for the booth).
ca::ChartData truth_chart(const ca::SpectralSet& refl, const ca::SpectralSet& lamp, const ca::SpectralSet& curves) {
  std::vector<double> grid;
  for (double w : lamp.wavelengths)
    if (w >= curves.wavelengths.front() && w <= curves.wavelengths.back()) grid.push_back(w);
  const auto r = ca::resample(refl, grid, ca::Interpolation::linear);
  const auto s = ca::resample(curves, grid, ca::Interpolation::linear);
  const auto l = ca::resample(lamp, grid, ca::Interpolation::linear);
  const Eigen::RowVectorXd e = l.values.row(0);
  const Eigen::MatrixXd raw = (r.values.array().rowwise() * e.array()).matrix() * s.values.transpose();
  const Eigen::RowVectorXd white = e * s.values.transpose();
  ca::ChartData c;
  c.ids = refl.names;
  c.rgb = raw.array().rowwise() / white.array();
  const ca::ReflectanceIntegrator integ(lamp, ca::load_observer(ca::Observer::cie1931_2deg), refl.wavelengths);
  const auto xyz = integ.xyz(refl);
  c.xyz.resize(static_cast<Eigen::Index>(xyz.size()), 3);
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    const ca::Xyz a = ca::bradford_adapt(xyz[i], integ.white(), ca::kIccD50White);
    c.xyz.row(static_cast<Eigen::Index>(i)) << a.X, a.Y, a.Z;
  }
  c.lab = ca::xyz_rows_to_lab(c.xyz, c.white);
  return c;
}

ca::SpectralSet camera(const ca::SpectralSet& cams, const std::string& name) {
  ca::SpectralSet s = cams.select({cams.require(name + "_R"), cams.require(name + "_G"), cams.require(name + "_B")});
  s.names = {"R", "G", "B"};
  return s;
}

// A small chart of smooth reflectances (380–730 nm, 10 nm) and three smooth curves with an uncertain posterior:
// enough for the band's arithmetic, nothing of a real camera.
ca::SpectralSet smooth_chart(int patches) {
  ca::SpectralSet refl;
  refl.wavelengths = ca::uniform_grid(380, 730, 10);
  refl.values.resize(patches, static_cast<Eigen::Index>(refl.wavelengths.size()));
  for (int i = 0; i < patches; ++i) {
    refl.names.push_back("p" + std::to_string(i));
    for (std::size_t j = 0; j < refl.wavelengths.size(); ++j)
      refl.values(i, static_cast<Eigen::Index>(j)) =
          0.5 + 0.4 * std::sin(0.3 * i + (refl.wavelengths[j] - 380) / (40.0 + 3 * i)) * std::cos(0.7 * i);
  }
  return refl;
}

ca::SensitivityEstimate smooth_sensitivities(const std::vector<double>& grid) {
  ca::SensitivityEstimate est;
  est.wavelengths = grid;
  est.curves.resize(3, static_cast<Eigen::Index>(grid.size()));
  for (int c = 0; c < 3; ++c) {
    for (std::size_t j = 0; j < grid.size(); ++j)
      est.curves(c, static_cast<Eigen::Index>(j)) = std::exp(-0.5 * std::pow((grid[j] - (600.0 - 70 * c)) / 35.0, 2));
    est.covariance[static_cast<std::size_t>(c)] = 1e-4 * Eigen::MatrixXd::Identity(est.curves.cols(), est.curves.cols());
  }
  return est;
}

}  // namespace

TEST(AcrossLamps, BeatsTheSameLampModelAndItsBandHoldsTheTruth) {
  COLORLAB_REQUIRE_SHARED(cams_file, "camera_ssf_camspec_jiang2013_28cams_10nm_400_720.csv");
  COLORLAB_REQUIRE_SHARED(sg_file, "colorcheckersg_isetcam_imai_lin_2010_10nm_380_730.csv");
  COLORLAB_REQUIRE_SHARED(cc_file, "colorchecker24_babelcolor_avg30_10nm_380_730.csv");
  COLORLAB_REQUIRE_SHARED(booth_file, "gretag_lightbooth_measured_spd_isetcam_2020_5nm_380_780.csv");
  const auto cams = ca::read_spectra(cams_file), sg = ca::read_spectra(sg_file), cc = ca::read_spectra(cc_file);
  const auto booth = ca::read_spectra(booth_file);
  const auto& grid = cams.wavelengths;
  const auto sg_d65 = ca::chart_under_lamp(sg, ca::nominal_lamp("D65"), grid);
  const std::vector<std::pair<std::string, std::string>> lamps = {{"A", "booth_A"}, {"F2", "booth_CWF"}};
  std::map<std::string, ca::ChartUnderLamp> assumed;
  for (const auto& [standard, measured] : lamps) assumed.emplace(standard, ca::chart_under_lamp(sg, ca::nominal_lamp(standard), grid));

  long inside_all = 0, patches_all = 0;
  // The Nokia N900 (a phone camera unlike the DSLRs of the prior) is the case whose band fell short when the nominal
  // lamp's own uncertainty was not carried (75–79 %, docs/ACCURACY.md §6).
  for (const std::string cam : {"Canon_20D", "Nikon_D3X", "Nokia_N900"}) {
    const auto curves = camera(cams, cam);
    ca::ChartData photo = truth_chart(sg, ca::resample(ca::load_illuminant("D65"), std::vector<double>(grid), ca::Interpolation::linear), curves);
    std::mt19937 rng(7);
    std::normal_distribution<double> nd(0, 1);
    for (Eigen::Index i = 0; i < photo.rgb.rows(); ++i)
      for (int c = 0; c < 3; ++c) photo.rgb(i, c) *= 1 + 0.005 * nd(rng);
    const auto est = ca::estimate_sensitivities(sg_d65, photo.rgb, ca::learn_sensitivity_prior(cams, grid, {cam}));

    ca::FitOptions fo;
    fo.input_scale = 1.0;
    const auto sel = ca::select_method(ca::all_methods(), kTargets, photo, fo, ca::CvSpec::loo());
    fo.target = sel.candidates[sel.chosen].target;
    const auto today = ca::fit_method(sel.candidates[sel.chosen].method, photo, fo);

    for (const auto& [standard, measured] : lamps) {
      SCOPED_TRACE(cam + " D65 → " + measured + " (model assumes CIE " + standard + ")");
      const auto test = truth_chart(cc, booth.select({booth.require(measured)}), curves);
      const auto relit = ca::characterize_across_lamps(est, assumed.at(standard));
      EXPECT_EQ(relit.lamp, standard);
      ASSERT_FALSE(relit.warnings.empty()) << "a nominal lamp must be warned about";
      const auto e = ca::evaluate(relit.apply(test.rgb), test.lab);
      const auto t = ca::evaluate(today.apply(test.rgb), test.lab);
      EXPECT_LT(e.s00.mean, t.s00.mean);
      EXPECT_LT(e.s00.max, t.s00.max);
      const Eigen::VectorXd band = relit.uncertainty95(test.rgb);
      long inside = 0;
      for (Eigen::Index i = 0; i < band.size(); ++i) inside += e.de00[static_cast<std::size_t>(i)] <= band(i);
      EXPECT_GE(static_cast<double>(inside) / static_cast<double>(band.size()), 0.80) << "issue 26: ≥ 80 % in every single case";
      inside_all += inside;
      patches_all += band.size();
      std::cout << cam << " → " << measured << ": across lamps " << relit.family << " " << e.s00.mean << " / " << e.s00.max
                << ", today " << t.s00.mean << " / " << t.s00.max << ", inside band " << inside << "/" << band.size() << "\n";
    }
  }
  const double pooled = static_cast<double>(inside_all) / static_cast<double>(patches_all);
  // The issue's 90–98 %: the lower end is asserted (the band is not overconfident). The upper end is not, here: over
  // 144 patches one patch is 0.7 %, and a 95 % band's count has a binomial standard deviation of 1.8 %; the bench
  // measures it over 9 cameras × 3 lamps (docs/ACCURACY.md §6).
  EXPECT_GE(pooled, 0.90) << "issue 26: the truth inside the 95 % band at 90–98 % over all cases";
}

TEST(AcrossLamps, NominalLampsAreWarnedAboutAndBadLampsAreTypedErrors) {
  const auto tl84 = ca::nominal_lamp("TL84");
  EXPECT_FALSE(tl84.measured);
  EXPECT_NE(tl84.warning().find("nominal"), std::string::npos);
  EXPECT_NE(tl84.warning().find("TL84"), std::string::npos);
  const auto m = ca::measured_lamp("TL84", tl84.spd);
  EXPECT_TRUE(m.measured);
  EXPECT_TRUE(m.warning().empty());
  try {
    (void)ca::nominal_lamp("sodium");
    FAIL() << "no standard for a sodium lamp";
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), colorlab::ErrorClass::not_found);
  }
  ca::SpectralSet bad = tl84.spd;
  bad.values(0, 3) = -1;
  EXPECT_THROW((void)ca::measured_lamp("TL84", bad), colorlab::Error);
  ca::SpectralSet two = tl84.spd;
  two.values.conservativeResize(2, Eigen::NoChange);
  two.values.row(1) = two.values.row(0);
  two.names.push_back("x");
  EXPECT_THROW((void)ca::measured_lamp("TL84", two), colorlab::Error);
}

// A nominal lamp's drawn spectrum departs from its standard by exp of a cubic in wavelength (Legendre degrees 1–3 over
// the grid, held constant beyond it): inside the grid the log ratio is reproduced exactly by the cubic through four of
// its points. A measured lamp is not drawn: its band is the same with the nominal lamp's uncertainty on or off.
TEST(AcrossLamps, NominalLampDrawsAreSmoothAndMeasuredLampsAreNotDrawn) {
  const auto a = ca::nominal_lamp("A");
  const std::vector<double> grid = ca::uniform_grid(400, 720, 10);
  std::mt19937 rng(3);
  const ca::SpectralSet drawn = ca::draw_nominal_lamp(a.spd, grid, rng);
  ASSERT_EQ(drawn.wavelengths, a.spd.wavelengths);
  std::vector<double> x, g;
  double below = NAN;  // the log ratio at the grid's first wavelength: held below it
  for (std::size_t j = 0; j < drawn.wavelengths.size(); ++j) {
    const double w = drawn.wavelengths[j];
    const auto c = static_cast<Eigen::Index>(j);
    const double r = std::log(drawn.values(0, c) / a.spd.values(0, c));
    if (w >= 400 && w <= 720) {
      if (x.empty()) below = r;
      x.push_back((w - 560) / 160);
      g.push_back(r);
    }
  }
  ASSERT_GE(x.size(), 8u);
  for (std::size_t j = 0; j < drawn.wavelengths.size() && drawn.wavelengths[j] < 400; ++j)
    EXPECT_NEAR(std::log(drawn.values(0, static_cast<Eigen::Index>(j)) / a.spd.values(0, static_cast<Eigen::Index>(j))), below, 1e-9);
  const std::array<std::size_t, 4> k = {0, x.size() / 3, 2 * x.size() / 3, x.size() - 1};
  for (std::size_t i = 0; i < x.size(); ++i) {
    double p = 0;
    for (std::size_t m = 0; m < 4; ++m) {
      double l = g[k[m]];
      for (std::size_t n = 0; n < 4; ++n)
        if (n != m) l *= (x[i] - x[k[n]]) / (x[k[m]] - x[k[n]]);
      p += l;
    }
    EXPECT_NEAR(g[i], p, 1e-9) << "at x = " << x[i];
  }
  bool changed = false;
  for (double v : g) changed |= std::abs(v) > 1e-6;
  EXPECT_TRUE(changed) << "a nominal lamp's draw must depart from its standard";

  const ca::SpectralSet refl = smooth_chart(30);
  const ca::SensitivityEstimate est = smooth_sensitivities(grid);
  const auto measured = ca::chart_under_lamp(refl, ca::measured_lamp("A", a.spd), grid);
  ca::AcrossLampsOptions on, off;
  on.methods = off.methods = {"ccm"};
  on.targets = off.targets = {ca::FitTarget::xyz_then_lab};
  on.draws = off.draws = 8;
  off.nominal_lamp_uncertainty = false;
  const auto rgb = measured.predict(est.curves).rgb;
  const Eigen::VectorXd band_on = ca::characterize_across_lamps(est, measured, on).uncertainty95(rgb);
  const Eigen::VectorXd band_off = ca::characterize_across_lamps(est, measured, off).uncertainty95(rgb);
  EXPECT_EQ(band_on, band_off) << "a measured lamp carries no nominal lamp's uncertainty";
  EXPECT_GT(band_on.minCoeff(), 0.0);
}

// The band's draws share what does not depend on the draw (the chart's resampling, the posterior's decomposition)
// and refit a spline without its hat matrix (issue 26's speed): the same arithmetic as rebuilding all of it per
// draw, so the same band to the last digit — and a chart rebuilt under another spectrum through the kept grids is the
// chart built from scratch under it.
TEST(AcrossLamps, BandSharingTheDrawsWorkEqualsRebuildingIt) {
  const std::vector<double> grid = ca::uniform_grid(400, 720, 10);
  const ca::SpectralSet refl = smooth_chart(40);
  const ca::SensitivityEstimate est = smooth_sensitivities(grid);
  const auto f11 = ca::chart_under_lamp(refl, ca::nominal_lamp("TL84"), grid);  // nominal: every draw draws the lamp too
  std::mt19937 rng(5);
  const ca::SpectralSet drawn = ca::draw_nominal_lamp(f11.lamp_spd, grid, rng);
  const auto kept = f11.under(drawn);
  const auto fresh = ca::chart_under_lamp(refl, ca::LampSpectrum{"TL84", drawn, false}, grid);
  EXPECT_EQ(kept.radiance, fresh.radiance);
  EXPECT_EQ(kept.white, fresh.white);
  EXPECT_EQ(kept.reference.xyz, fresh.reference.xyz);
  EXPECT_EQ(kept.reference.lab, fresh.reference.lab);

  for (const std::string method : {"rbf:ccm", "rootpoly:2"}) {
    SCOPED_TRACE(method);
    ca::AcrossLampsOptions shared, rebuilt;
    shared.methods = rebuilt.methods = {method};
    shared.targets = rebuilt.targets = {ca::FitTarget::xyz_then_lab};
    shared.draws = rebuilt.draws = 6;
    rebuilt.share_draw_work = false;
    const auto a = ca::characterize_across_lamps(est, f11, shared), b = ca::characterize_across_lamps(est, f11, rebuilt);
    ASSERT_EQ(a.family, method);
    const auto rgb = f11.predict(est.curves).rgb;
    const Eigen::VectorXd band = a.uncertainty95(rgb);
    EXPECT_EQ(band, b.uncertainty95(rgb));
    EXPECT_EQ(a.apply(rgb), b.apply(rgb));
    EXPECT_GT(band.minCoeff(), 0.0);
  }
}
