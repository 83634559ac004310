// The chart in the scene: where its spectra come from and where its patches are.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/csv.hpp"
#include "colorlab/core/data_paths.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/sim/scene.hpp"

namespace colorlab::sim {
namespace {

constexpr const char* kSgFile = "colorcheckersg_xrite_before_nov2014_dcamprof_10nm_380_730.csv";

std::filesystem::path temp_file(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("colorlab_sim_scene_" + std::to_string(::getpid()) + "_" + name);
}

TEST(SimChart, SharedSgSpectraReproduceXRitesPublishedLab) {
  const auto spectra = paths::shared_data_file(kSgFile);
  const auto lab_file = paths::shared_data_file("colorcheckersg_xrite_lab_d50.csv");
  if (!spectra || !lab_file) GTEST_SKIP() << "shared data set not present (" << kSgFile << ")";
  const Scene scene(SceneConfig{}, std::make_shared<SimClock>());
  const Chart& chart = scene.chart();
  ASSERT_EQ(chart.patches.size(), 140u);
  EXPECT_EQ(chart.source, spectra->string());
  EXPECT_DOUBLE_EQ(chart.patches[0].reflectance.values[0], 0.1291);  // A1 at 380 nm, straight from the file

  // Independent truth: X-Rite's published D50 L*a*b* for the same (pre-Nov-2014) chart.
  const auto published = analysis::read_csv(*lab_file);
  const auto d50 = analysis::load_illuminant("D50");
  const auto observer = analysis::load_observer(analysis::Observer::cie1931_2deg);
  const analysis::ReflectanceIntegrator integrate(d50, observer, analysis::uniform_grid(380, 730, 10));
  double sum_de = 0, max_de = 0;
  for (std::size_t r = 0; r < published.rows.size(); ++r) {
    const auto idx = chart.index_of(published.rows[r][0]);
    ASSERT_TRUE(idx) << published.rows[r][0];
    const auto& v = chart.patches[static_cast<std::size_t>(*idx)].reflectance.values;
    const Eigen::RowVectorXd refl = Eigen::Map<const Eigen::RowVectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
    const auto lab = analysis::xyz_to_lab(integrate.xyz(refl), integrate.white());
    const double de = std::hypot(lab.L - published.number(r, 1), lab.a - published.number(r, 2),
                                 lab.b - published.number(r, 3));
    sum_de += de;
    max_de = std::max(max_de, de);
  }
  const double mean_de = sum_de / double(published.rows.size());
  std::printf("chart vs X-Rite Lab D50: mean dE76 %.3f max %.3f\n", mean_de, max_de);
  EXPECT_LT(mean_de, 0.3);
  EXPECT_LT(max_de, 1.5);
}

TEST(SimChart, SyntheticChartIsPlausibleAndIndependentOfTheSeed) {
  SceneConfig cfg;
  cfg.force_synthetic_chart = true;
  cfg.seed = 99;
  const Scene a(cfg, std::make_shared<SimClock>());
  cfg.seed = 100;
  const Scene b(cfg, std::make_shared<SimClock>());
  const Chart& chart = a.chart();
  EXPECT_EQ(chart.source, "synthetic");
  ASSERT_EQ(chart.patches.size(), 140u);
  for (std::size_t i = 0; i < chart.patches.size(); ++i) {
    const auto& s = chart.patches[i].reflectance;
    ASSERT_EQ(s.values.size(), 36u);
    EXPECT_DOUBLE_EQ(s.start_nm, 380);
    EXPECT_EQ(s.values, b.chart().patches[i].reflectance.values);
    for (std::size_t k = 0; k < s.values.size(); ++k) {
      EXPECT_GE(s.values[k], 0.01);
      EXPECT_LE(s.values[k], 0.95);
      if (k > 0) {
        EXPECT_LT(std::abs(s.values[k] - s.values[k - 1]), 0.2) << chart.patches[i].name;  // smooth
      }
    }
  }
  // The border is neutral: white, black and grey alternate, as on the SG.
  const auto& a1 = chart.patches[*chart.index_of("A1")].reflectance.values;
  EXPECT_GT(a1[20], 0.8);
  EXPECT_LT(std::abs(a1[10] - a1[30]), 0.01);
}

TEST(SimChart, ReadsArgyllStyleCgatsInPercent) {
  const auto path = temp_file("chart.ti3");
  {
    std::ofstream out(path);
    out << "CTI3\n\nDESCRIPTOR \"test\"\nNUMBER_OF_FIELDS 37\nBEGIN_DATA_FORMAT\nSAMPLE_ID";
    for (int nm = 380; nm <= 730; nm += 10) out << " SPEC_" << nm;
    out << "\nEND_DATA_FORMAT\nNUMBER_OF_SETS 140\nBEGIN_DATA\n";
    for (char col = 'A'; col <= 'N'; ++col)
      for (int row = 1; row <= 10; ++row) {
        out << col << row;
        for (int nm = 380; nm <= 730; nm += 10) out << ' ' << (10.0 + (col - 'A') + 0.01 * (nm - 380));
        out << '\n';
      }
    out << "END_DATA\n";
  }
  SceneConfig cfg;
  cfg.chart_file = path;
  const Scene scene(cfg, std::make_shared<SimClock>());
  const auto& c3 = scene.chart().patches[*scene.chart().index_of("C3")].reflectance;
  EXPECT_NEAR(c3.at(380), 0.12, 1e-9);
  EXPECT_NEAR(c3.at(730), 0.12 + 0.035, 1e-9);
  std::filesystem::remove(path);
}

TEST(SimChart, BadFilesGiveTypedErrors) {
  SceneConfig cfg;
  cfg.chart_file = "/nonexistent/chart.csv";
  try {
    Scene s(cfg, std::make_shared<SimClock>());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::not_found);
  }
  const auto path = temp_file("short.csv");
  {
    std::ofstream out(path);
    out << "wavelength_nm,A1,A2\n380,0.1,0.2\n390,0.1,0.2\n";
  }
  cfg.chart_file = path;
  try {
    Scene s(cfg, std::make_shared<SimClock>());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_data);
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(SimChart, PatchGeometryRoundTripsAndSitsInTheFrontMiddle) {
  SceneConfig cfg;
  cfg.force_synthetic_chart = true;
  const Scene scene(cfg, std::make_shared<SimClock>());
  const Chart& chart = scene.chart();
  for (int i = 0; i < chart_patch_count; ++i) {
    const auto& p = chart.patches[static_cast<std::size_t>(i)];
    EXPECT_EQ(chart.patch_at(p.x_mm + p.size_mm / 2, p.y_mm + p.size_mm / 2), i);
    EXPECT_EQ(chart.patch_at(p.x_mm - 0.5, p.y_mm + 1), std::nullopt);  // the gap between patches
    const auto [fx, fy] = scene.patch_floor_position_mm(i);
    EXPECT_GT(fx, 600 - chart_width_mm / 2);
    EXPECT_LT(fx, 600 + chart_width_mm / 2);
    EXPECT_GT(fy, 0);
    EXPECT_LT(fy, 4 * floor_spot_pitch_y_mm + 40);
  }
  EXPECT_EQ(chart.patch_at(0.5, 0.5), std::nullopt);
  EXPECT_THROW(scene.patch_floor_position_mm(140), Error);
  // Row 1 is at the back of the cabinet, row 10 at the front: the field makes them differ.
  EXPECT_GT(scene.patch_floor_position_mm(*chart.index_of("A1")).second,
            scene.patch_floor_position_mm(*chart.index_of("A10")).second);
}

}  // namespace
}  // namespace colorlab::sim

namespace colorlab::sim {
namespace {

// The scene's patch truth equals plain colorimetry of its own spectra: reflectance × lamp SPD → XYZ → Lab
// (computed here by analysis' ReflectanceIntegrator on the CIE table colord ships, not by the scene).
TEST(SimChart, PatchLabTruthIsColorimetryOfTheScenesOwnSpectra) {
  for (Lamp lamp : {Lamp::d65, Lamp::tl84, Lamp::a}) {
    SceneConfig cfg;
    cfg.force_synthetic_chart = true;
    cfg.lamps_on_at_start = {lamp};
    cfg.dimmer_percent_at_start = 70;
    const Scene scene(cfg, std::make_shared<SimClock>());
    const auto illuminant = analysis::load_illuminant(lamp == Lamp::d65 ? "D65" : lamp == Lamp::tl84 ? "F11"
                                                                                                     : "A");
    const auto observer = analysis::load_observer(analysis::Observer::cie1931_2deg);
    analysis::IntegrationOptions opt;
    opt.step_nm = 5;
    opt.reflectance = analysis::Interpolation::linear;
    const analysis::ReflectanceIntegrator integrate(illuminant, observer, analysis::uniform_grid(380, 730, 10), opt);
    double worst = 0;
    for (int i = 0; i < chart_patch_count; ++i) {
      const auto& v = scene.chart().patches[static_cast<std::size_t>(i)].reflectance.values;
      const Eigen::RowVectorXd refl = Eigen::Map<const Eigen::RowVectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
      const auto expected = analysis::xyz_to_lab(integrate.xyz(refl), integrate.white());
      const auto got = scene.patch_lab(i);
      worst = std::max(worst, std::hypot(got[0] - expected.L, got[1] - expected.a, got[2] - expected.b));
    }
    std::printf("%s: worst dE76 scene truth vs colorimetry %.4f\n", std::string(to_string(lamp)).c_str(), worst);
    // The scene samples lamps and reflectances on a 5 nm grid; the integrator uses its own quadrature on 380–730
    // nm, so a few hundredths of a ΔE remain for the steeply rising A.
    EXPECT_LT(worst, 0.1) << to_string(lamp);
  }
}

}  // namespace
}  // namespace colorlab::sim

namespace colorlab::sim {
namespace {

TEST(SimTable, ApertureSeesPatchesSurroundAndPlate) {
  SceneConfig cfg;
  cfg.force_synthetic_chart = true;
  const Scene scene(cfg, std::make_shared<SimClock>());
  const Chart& chart = scene.chart();
  for (int i = 0; i < chart_patch_count; i += 13) {
    const auto& p = chart.patches[static_cast<std::size_t>(i)];
    const auto s = scene.table_sample(cfg.chart_on_table_x_mm + p.x_mm + p.size_mm / 2,
                                      cfg.chart_on_table_y_mm + p.y_mm + p.size_mm / 2);
    ASSERT_TRUE(s.patch);
    EXPECT_EQ(*s.patch, i);
    EXPECT_EQ(s.reflectance->values, p.reflectance.values);
  }
  const auto corner = scene.table_sample(2, 2);
  EXPECT_FALSE(corner.patch);
  EXPECT_NEAR(corner.reflectance->at(550), 0.8, 1e-12);
  const auto gap = scene.table_sample(cfg.chart_on_table_x_mm + 1, cfg.chart_on_table_y_mm + 1);
  EXPECT_FALSE(gap.patch);
  EXPECT_LT(gap.reflectance->at(550), 0.1);
  EXPECT_THROW(scene.table_sample(311, 10), Error);
  EXPECT_THROW(scene.table_sample(10, -0.1), Error);
}

}  // namespace
}  // namespace colorlab::sim

namespace colorlab::sim {
namespace {

// Tuning: checks the simulator's tuning to the dissertation, not the analysis; the analysis is checked by
// AnalyticTruthUniformity.* (analysis_analytic_truth_test).
// §6.2's reason for choosing the chart position: equal white border patches must not differ much, but the
// field's non-uniformity does show on them.
TEST(SimChart, FieldNonUniformityShowsOnIdenticalBorderPatches) {
  SceneConfig cfg;
  cfg.force_synthetic_chart = true;
  cfg.lamps_on_at_start = {Lamp::d65};
  const Scene scene(cfg, std::make_shared<SimClock>());
  const auto& patches = scene.chart().patches;
  double lo = 1e300, hi = 0;
  int whites = 0;
  for (int i = 0; i < chart_patch_count; ++i) {
    if (patches[static_cast<std::size_t>(i)].reflectance.values != patches[0].reflectance.values) continue;
    const double y = scene.patch_xyz(i)[1];
    lo = std::min(lo, y);
    hi = std::max(hi, y);
    ++whites;
  }
  std::printf("%d identical white patches: luminance %.1f..%.1f cd/m2 (%.1f %%)\n", whites, lo, hi, 100 * (hi / lo - 1));
  EXPECT_GE(whites, 8);
  EXPECT_GT(hi / lo, 1.02);
  EXPECT_LT(hi / lo, 1.20);
  // Switching the lamp to CWF (less uniform) widens the spread.
  SceneConfig cwf = cfg;
  cwf.lamps_on_at_start = {Lamp::cwf};
  const Scene cwf_scene(cwf, std::make_shared<SimClock>());
  double clo = 1e300, chi = 0;
  for (int i = 0; i < chart_patch_count; ++i) {
    if (patches[static_cast<std::size_t>(i)].reflectance.values != patches[0].reflectance.values) continue;
    const double y = cwf_scene.patch_xyz(i)[1];
    clo = std::min(clo, y);
    chi = std::max(chi, y);
  }
  EXPECT_GT(chi / clo, hi / lo);
}

}  // namespace
}  // namespace colorlab::sim
