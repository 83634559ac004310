// File readers and resampling: CGATS as Argyll/colord write it, CSV, colord's standard tables, interpolation.
#include <gtest/gtest.h>

#include <cmath>

#include "colorlab/analysis/cgats.hpp"
#include "colorlab/analysis/chart_io.hpp"
#include "colorlab/analysis/csv.hpp"
#include "colorlab/analysis/spectral.hpp"
#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/core/error.hpp"
#include "test_support.hpp"

namespace ca = colorlab::analysis;

namespace {

const char* kTi3 = R"(CTI3   # a comment

DESCRIPTOR "Argyll Calibration Target chart information 3"
ORIGINATOR "Argyll target"
CREATED "Sat Nov 21 2026"
KEYWORD "DEVICE_CLASS"
DEVICE_CLASS "INPUT"
KEYWORD "SPECTRAL_BANDS"
SPECTRAL_BANDS "3"
SPECTRAL_START_NM "400.0"
SPECTRAL_END_NM "420.0"
SPECTRAL_NORM "100.0"

NUMBER_OF_FIELDS 7
BEGIN_DATA_FORMAT
SAMPLE_ID SAMPLE_LOC RGB_R SPEC_400 SPEC_410
SPEC_420 XYZ_X
END_DATA_FORMAT

NUMBER_OF_SETS 2
BEGIN_DATA
1 "A 1" 50.0 10 20 30 1.5
2 "B 2" 25.5 40 50 60 2.5
END_DATA

CAL

DESCRIPTOR "second table"
NUMBER_OF_FIELDS 2
BEGIN_DATA_FORMAT
RGB_I RGB_R
END_DATA_FORMAT
NUMBER_OF_SETS 1
BEGIN_DATA
0 0
END_DATA
)";

TEST(AnalysisCgats, ParsesArgyllTi3WithQuotesCommentsAndTwoTables) {
  auto tables = ca::parse_cgats(kTi3, "mem.ti3");
  ASSERT_EQ(tables.size(), 2u);
  const auto& t = tables[0];
  EXPECT_EQ(t.file_type, "CTI3");
  EXPECT_EQ(t.keyword("DEVICE_CLASS").value(), "INPUT");
  ASSERT_EQ(t.fields.size(), 7u);
  EXPECT_EQ(t.rows[1][1], "B 2");
  EXPECT_DOUBLE_EQ(t.number(1, "RGB_R"), 25.5);
  EXPECT_EQ(tables[1].file_type, "CAL");
  ca::SpectralSet s = ca::spectra_from_cgats(t);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s.names[0], "1");
  EXPECT_DOUBLE_EQ(s.wavelengths[2], 420.0);
  EXPECT_DOUBLE_EQ(s.values(1, 2), 0.60);  // percent → fraction by SPECTRAL_NORM
}

TEST(AnalysisCgats, FormatThenParseRoundTrips) {
  auto t = ca::parse_cgats(kTi3, "mem.ti3").front();
  auto again = ca::parse_cgats(ca::format_cgats(t), "again").front();
  EXPECT_EQ(again.fields, t.fields);
  EXPECT_EQ(again.rows, t.rows);
  EXPECT_EQ(again.keyword("SPECTRAL_NORM").value(), "100.0");
}

TEST(AnalysisCgats, MalformedFilesGiveTypedErrorsWithLocation) {
  auto expect_bad = [](const std::string& text, const std::string& needle) {
    try {
      ca::parse_cgats(text, "bad.ti3");
      FAIL() << "no error for: " << needle;
    } catch (const colorlab::Error& e) {
      EXPECT_EQ(e.cls(), colorlab::ErrorClass::bad_data);
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_bad("CTI3\nBEGIN_DATA_FORMAT\nA B\nEND_DATA_FORMAT\nBEGIN_DATA\n1 2 3\nEND_DATA\n", "bad.ti3:6");
  expect_bad("CTI3\nNUMBER_OF_SETS 3\nBEGIN_DATA_FORMAT\nA\nEND_DATA_FORMAT\nBEGIN_DATA\n1\nEND_DATA\n", "NUMBER_OF_SETS");
  expect_bad("CTI3\nBEGIN_DATA_FORMAT\nA\nEND_DATA_FORMAT\nBEGIN_DATA\n1\n", "missing END_DATA");
  expect_bad("CTI3\nDESCRIPTOR \"open\nBEGIN_DATA\n", "unterminated");
  expect_bad("", "no CGATS data table");
  auto t = ca::parse_cgats("X\nBEGIN_DATA_FORMAT\nSPEC_400 SPEC_410\nEND_DATA_FORMAT\nBEGIN_DATA\n1 abc\nEND_DATA\n", "m.sp");
  EXPECT_THROW(ca::spectra_from_cgats(t.front()), colorlab::Error);
}

TEST(AnalysisCsv, ReadsHeaderQuotesAndTrailingCommas) {
  auto t = ca::parse_csv("wavelength_nm,a,\"b,c\",\n400,0.1,0.2,\n410,0.3,0.4,\n", "m.csv");
  ASSERT_EQ(t.header.size(), 3u);
  EXPECT_EQ(t.header[2], "b,c");
  auto s = ca::spectra_from_csv(t);
  EXPECT_EQ(s.size(), 2u);
  EXPECT_DOUBLE_EQ(s.values(1, 1), 0.4);
  EXPECT_THROW(ca::parse_csv("a,b\n1,2,3,4\n", "m.csv"), colorlab::Error);
  EXPECT_THROW(ca::read_csv("/nonexistent/file.csv"), colorlab::Error);
}

TEST(AnalysisStandardData, ColordObserversAndIlluminants) {
  auto obs = ca::load_observer(ca::Observer::cie1931_2deg);
  ASSERT_EQ(obs.size(), 3u);
  EXPECT_DOUBLE_EQ(obs.wavelengths.front(), 360);
  EXPECT_DOUBLE_EQ(obs.wavelengths.back(), 830);
  // ȳ(555 nm) = 1 by definition.
  auto i555 = std::find(obs.wavelengths.begin(), obs.wavelengths.end(), 555.0) - obs.wavelengths.begin();
  EXPECT_NEAR(obs.values(1, i555), 1.0, 1e-6);
  // colord's CIE-A.sp misnames its fields (SPEC_300000); the keywords give 300–830 nm at 1 nm.
  auto a = ca::load_illuminant("A");
  EXPECT_DOUBLE_EQ(a.wavelengths.front(), 300);
  EXPECT_DOUBLE_EQ(a.wavelengths[1], 301);
  EXPECT_DOUBLE_EQ(a.wavelengths.back(), 830);
  auto i560 = std::find(a.wavelengths.begin(), a.wavelengths.end(), 560.0) - a.wavelengths.begin();
  EXPECT_NEAR(a.values(0, i560), 1.0, 1e-4);  // colord normalises A to 1 at 560 nm
  EXPECT_EQ(ca::load_illuminant("f11").names[0], "CIE-F11");
  EXPECT_THROW(ca::load_illuminant("D42"), colorlab::Error);
  EXPECT_THROW(ca::load_illuminant("../x"), colorlab::Error);
  EXPECT_THROW(ca::observer_from_degrees(4), colorlab::Error);
}

double f(double x) { return std::exp(-std::pow((x - 550) / 60, 2)); }

TEST(AnalysisResampling, InterpolatorsReproduceNodesPolynomialsAndSmoothCurves) {
  auto from = ca::uniform_grid(380, 730, 10);
  auto to = ca::uniform_grid(380, 730, 1);
  Eigen::VectorXd quad(static_cast<Eigen::Index>(from.size())), lin(quad.size()), g(quad.size());
  for (std::size_t i = 0; i < from.size(); ++i) {
    double x = (from[i] - 500) / 100;
    quad(static_cast<Eigen::Index>(i)) = 1 + x + 0.5 * x * x;
    lin(static_cast<Eigen::Index>(i)) = 2 - x;
    g(static_cast<Eigen::Index>(i)) = f(from[i]);
  }
  auto S = ca::resampling_matrix(from, to, ca::Interpolation::sprague);
  auto C = ca::resampling_matrix(from, to, ca::Interpolation::cubic_spline);
  auto L = ca::resampling_matrix(from, to, ca::Interpolation::linear);
  Eigen::VectorXd sq = S * quad, cl = C * lin, sg = S * g, cg = C * g, lg = L * g;
  double es = 0, ec = 0, el = 0;
  for (std::size_t k = 0; k < to.size(); ++k) {
    double x = (to[k] - 500) / 100;
    auto kk = static_cast<Eigen::Index>(k);
    // Sprague is exact for low-order polynomials away from the CIE's extrapolated end points.
    if (to[k] >= from[2] && to[k] <= from[from.size() - 3]) {
      EXPECT_NEAR(sq(kk), 1 + x + 0.5 * x * x, 1e-9) << to[k];
    }
    EXPECT_NEAR(cl(kk), 2 - x, 1e-9) << to[k];  // natural spline is exact for lines
    es = std::max(es, std::abs(sg(kk) - f(to[k])));
    ec = std::max(ec, std::abs(cg(kk) - f(to[k])));
    el = std::max(el, std::abs(lg(kk) - f(to[k])));
  }
  EXPECT_LT(es, 2e-4);
  EXPECT_LT(ec, 2e-3);
  EXPECT_LT(es, el / 5);  // smooth interpolators beat linear on a smooth spectrum
  EXPECT_THROW(ca::resampling_matrix(from, {370.0}, ca::Interpolation::linear), colorlab::Error);
  EXPECT_THROW(ca::resampling_matrix({400, 410, 430, 440, 450, 460}, {405}, ca::Interpolation::sprague), colorlab::Error);
}

TEST(AnalysisChartIo, SgPatchNumberingIsTheDissertations) {
  EXPECT_EQ(ca::sg_patch_id(1), "A1");
  EXPECT_EQ(ca::sg_patch_id(14), "N1");
  EXPECT_EQ(ca::sg_patch_id(15), "A2");
  EXPECT_EQ(ca::sg_patch_id(140), "N10");
  for (int n = 1; n <= 140; ++n) EXPECT_EQ(ca::sg_patch_number(ca::sg_patch_id(n)), n);
  EXPECT_THROW(ca::sg_patch_id(141), colorlab::Error);
  EXPECT_THROW(ca::sg_patch_number("O1"), colorlab::Error);
}

TEST(AnalysisChartIo, ReadsTestVectorsAndWritesTi3ThatReadsBack) {
  COLORLAB_REQUIRE_SHARED(file, "testvec_cc24_canon20d_d50_argyll.csv");
  ca::ChartData c = ca::read_chart(file);
  ASSERT_EQ(c.size(), 24u);
  EXPECT_NEAR(c.lab(0, 0), 38.4245, 1e-6);
  auto dir = ca::testing::temp_dir("io");
  ca::write_argyll_ti3(dir / "c.ti3", c);
  ca::ChartData back = ca::read_chart(dir / "c.ti3");
  EXPECT_NEAR((back.rgb - c.rgb).cwiseAbs().maxCoeff(), 0.0, 1e-8);
  EXPECT_NEAR((back.xyz - c.xyz).cwiseAbs().maxCoeff(), 0.0, 1e-6);
}

}  // namespace
