// Bad input everywhere: typed colorlab::Error saying what and where, never a crash or silent garbage.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "colorlab/analysis/blackbox.hpp"
#include "colorlab/analysis/chart_io.hpp"
#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/patch_stats.hpp"
#include "colorlab/analysis/regression.hpp"
#include "colorlab/core/error.hpp"
#include "test_support.hpp"

namespace ca = colorlab::analysis;
using colorlab::ErrorClass;

namespace {

template <class F>
void expect_error(F&& f, ErrorClass cls, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one mentioning '" << needle << "'";
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), cls) << e.what();
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

ca::SpectralSet flat_reflectance(double v) {
  ca::SpectralSet s;
  s.wavelengths = ca::uniform_grid(380, 730, 10);
  s.names = {"P1", "P2"};
  s.values = Eigen::MatrixXd::Constant(2, 36, v);
  s.source = "mem.csv";
  return s;
}

TEST(AnalysisBadInput, NanAndNegativeSpectraNameSampleAndWavelength) {
  auto lamp = ca::load_illuminant("D65");
  auto s = flat_reflectance(0.5);
  s.values(1, 7) = NAN;
  expect_error([&] { ca::reflectance_to_xyz(s, lamp, ca::Observer::cie1931_2deg); }, ErrorClass::bad_data, "'P2' at 450 nm");
  s.values(1, 7) = -0.2;
  expect_error([&] { ca::reflectance_to_xyz(s, lamp, ca::Observer::cie1931_2deg); }, ErrorClass::bad_data, "negative");
  ca::SpectralSet bad_lamp = lamp;
  bad_lamp.values(0, 3) = -1;
  expect_error([&] { ca::illuminant_white(bad_lamp, ca::Observer::cie1931_2deg); }, ErrorClass::bad_data, "emission spectrum");
}

TEST(AnalysisBadInput, MismatchedGridsAndPatchCounts) {
  auto lamp = ca::load_illuminant("D65");
  ca::ReflectanceIntegrator integ(lamp, ca::load_observer(ca::Observer::cie1931_2deg), ca::uniform_grid(400, 700, 10));
  expect_error([&] { integ.xyz(flat_reflectance(0.5)); }, ErrorClass::bad_data, "wavelength grid differs");
  auto s = flat_reflectance(0.5);
  s.wavelengths.pop_back();
  expect_error([&] { s.check_shape(); }, ErrorClass::bad_data, "36 values per spectrum but 35 wavelengths");
  ca::ChartData c;
  c.ids = {"a", "b", "c"};
  c.rgb = Eigen::MatrixXd::Ones(3, 3);
  c.xyz = Eigen::MatrixXd::Ones(2, 3);
  c.lab = Eigen::MatrixXd::Ones(3, 3);
  expect_error([&] { ca::fit("poly:1", c); }, ErrorClass::bad_data, "chart XYZ has 2x3 values for 3 patches");
  c.xyz = Eigen::MatrixXd::Ones(3, 3);
  c.rgb(1, 2) = NAN;
  expect_error([&] { ca::fit("poly:1", c); }, ErrorClass::bad_data, "RGB of patch b");
  expect_error([&] { ca::fit_blackbox(Eigen::MatrixXd::Ones(5, 10), Eigen::MatrixXd::Ones(4, 3)); }, ErrorClass::bad_data,
               "5 spectra but 4 RAW");
}

// Camera-curve collections for the black-box prior: too few cameras, a grid they do not cover, a dead channel.
TEST(AnalysisBadInput, SensitivityPriorCurves) {
  ca::SpectralSet curves;
  curves.source = "cams.csv";
  curves.wavelengths = {400, 500, 600, 700};
  for (const char* cam : {"A", "B", "C"})
    for (const char* ch : {"_R", "_G", "_B"}) curves.names.push_back(std::string(cam) + ch);
  curves.values = Eigen::MatrixXd::Random(9, 4).cwiseAbs() + Eigen::MatrixXd::Constant(9, 4, 0.1);
  EXPECT_EQ(ca::learn_sensitivity_prior(curves, {400, 450, 500}).cameras.size(), 3u);
  expect_error([&] { ca::learn_sensitivity_prior(curves, {400, 450, 500}, {"B"}); }, ErrorClass::bad_data, "2 complete cameras");
  expect_error([&] { ca::learn_sensitivity_prior(curves, {380, 400, 500}); }, ErrorClass::bad_data, "do not cover");
  curves.values.row(4).setZero();  // B_G
  expect_error([&] { ca::learn_sensitivity_prior(curves, {400, 450, 500}); }, ErrorClass::bad_data, "'B_G' in cams.csv");
  curves.values.row(4).setOnes();
  ca::BlackBoxOptions o;
  o.prior = ca::learn_sensitivity_prior(curves, {400, 450, 500});
  expect_error([&] { ca::fit_blackbox(Eigen::MatrixXd::Ones(5, 4), Eigen::MatrixXd::Ones(5, 3), o); }, ErrorClass::bad_data,
               "prior has 3 bands, spectra 4");
}

TEST(AnalysisBadInput, EmptyRegionsAndOutOfImageRegions) {
  std::vector<float> px(100, 1.0f);
  ca::ImageView v{px.data(), 10, 10, 10};
  expect_error([&] { ca::robust_patch_value(v, {2, 2, 0, 5}); }, ErrorClass::bad_data, "is empty");
  expect_error([&] { ca::robust_patch_value(v, {8, 8, 5, 5}); }, ErrorClass::bad_data, "leaves the 10x10 image");
  ca::PixelMask all{10, 10, std::vector<std::uint8_t>(100, 1)};
  expect_error([&] { ca::robust_patch_value(v, {0, 0, 3, 3}, {}, &all); }, ErrorClass::bad_data, "no usable");
}

TEST(AnalysisBadInput, RankDeficientDesigns) {
  ca::ChartData c;
  c.ids = {"a", "b", "c", "d"};
  c.rgb = Eigen::MatrixXd::Random(4, 3).cwiseAbs();
  c.xyz = Eigen::MatrixXd::Constant(4, 3, 20);
  c.lab = ca::xyz_rows_to_lab(c.xyz, c.white);
  expect_error([&] { ca::fit("poly:6", c); }, ErrorClass::bad_data, "4 patches cannot determine 11 terms");
  c.rgb.col(1) = c.rgb.col(0);  // g = r on every patch: rg and r² coincide
  expect_error([&] { ca::fit("poly:3", c); }, ErrorClass::bad_data, "rank");
}

TEST(AnalysisBadInput, UnreadableAndMalformedFiles) {
  expect_error([] { ca::read_spectra("/nonexistent/dir/x.sp"); }, ErrorClass::io_error, "/nonexistent/dir/x.sp");
  expect_error([] { ca::read_chart("/nonexistent/chart.csv"); }, ErrorClass::io_error, "chart.csv");
  auto dir = ca::testing::temp_dir("bad");
  {
    std::ofstream(dir / "s.csv") << "wavelength_nm,a\n400,0.1\n410,zero\n";
    std::ofstream(dir / "chart.csv") << "patch_id,R,G,B\nA1,0.1,0.2,0.3\n";
  }
  expect_error([&] { ca::read_spectra(dir / "s.csv"); }, ErrorClass::bad_data, "s.csv:3, column 'a': 'zero'");
  expect_error([&] { ca::read_chart(dir / "chart.csv"); }, ErrorClass::bad_data, "X,Y,Z or L,a,b");
}

}  // namespace
