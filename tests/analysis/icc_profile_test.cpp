// Chapter 7 (b): input profiles built with lcms2 from chart data, applied with lcms2 and read back by ArgyllCMS.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "colorlab/analysis/chart_io.hpp"
#include "colorlab/analysis/color_difference.hpp"
#include "colorlab/analysis/icc_profile.hpp"
#include "colorlab/core/error.hpp"
#include "test_support.hpp"

namespace ca = colorlab::analysis;

namespace {

// Lab of device values through Argyll's xicclu (an ICC implementation independent of lcms2).
Eigen::MatrixXd xicclu(const std::filesystem::path& icc, const Eigen::MatrixXd& rgb, const std::filesystem::path& dir) {
  {
    std::ofstream in(dir / "in.txt");
    in.precision(10);
    for (Eigen::Index i = 0; i < rgb.rows(); ++i) in << rgb(i, 0) << " " << rgb(i, 1) << " " << rgb(i, 2) << "\n";
  }
  const std::string cmd = "xicclu -v0 -ff -ia -pl '" + icc.string() + "' < '" + (dir / "in.txt").string() + "' > '" +
                          (dir / "out.txt").string() + "' 2>/dev/null";
  if (std::system(cmd.c_str()) != 0) return {};
  std::ifstream out(dir / "out.txt");
  Eigen::MatrixXd lab(rgb.rows(), 3);
  for (Eigen::Index i = 0; i < rgb.rows(); ++i)
    if (!(out >> lab(i, 0) >> lab(i, 1) >> lab(i, 2))) return {};
  return lab;
}

double max_de00(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  double m = 0;
  for (Eigen::Index i = 0; i < a.rows(); ++i)
    m = std::max(m, ca::delta_e2000({a(i, 0), a(i, 1), a(i, 2)}, {b(i, 0), b(i, 1), b(i, 2)}));
  return m;
}

TEST(AnalysisIccProfile, MatrixShaperReproducesTheFittedMatrixInLcmsAndArgyll) {
  COLORLAB_REQUIRE_SHARED(cc24, "testvec_cc24_canon20d_d50_argyll.csv");
  ca::ChartData c = ca::read_chart(cc24);
  auto profile = ca::build_matrix_shaper_profile(c);
  ca::FitOptions o;
  o.input_scale = 1.0;
  const Eigen::MatrixXd direct = ca::fit("ccm", c, o).apply(c.rgb);
  const Eigen::MatrixXd via_lcms = ca::apply_profile(profile, c.rgb);
  EXPECT_LT(max_de00(direct, via_lcms), 2e-3);  // s15Fixed16 colorants
  auto e = ca::evaluate(via_lcms, c.lab);
  std::cout << "matrix/shaper profile on CC24: dE76 mean " << e.s76.mean << ", dE00 mean " << e.s00.mean << "\n";
  if (!ca::testing::have_tool("xicclu")) GTEST_SKIP() << "xicclu not installed (argyll): Argyll cross-check skipped";
  auto dir = ca::testing::temp_dir("icc");
  profile.save(dir / "m.icc");
  Eigen::MatrixXd argyll = xicclu(dir / "m.icc", c.rgb, dir);
  ASSERT_EQ(argyll.rows(), c.rgb.rows()) << "xicclu could not read the profile";
  EXPECT_LT(max_de00(argyll, via_lcms), 2e-3);
}

TEST(AnalysisIccProfile, LutProfileFromTheSelectedModel) {
  COLORLAB_REQUIRE_SHARED(sg, "testvec_sg140_canon20d_d50_argyll.csv");
  COLORLAB_REQUIRE_SHARED(cc24, "testvec_cc24_canon20d_d50_argyll.csv");
  ca::ChartData train = ca::read_chart(sg), test = ca::read_chart(cc24);
  ca::FitOptions o;
  o.input_scale = 1.0;
  o.target = ca::FitTarget::xyz_lightness_weighted;
  auto model = ca::fit("rootpoly:3", train, o);
  auto profile = ca::build_lut_profile(model, 33);
  const Eigen::MatrixXd direct = model.apply(test.rgb), via_lcms = ca::apply_profile(profile, test.rgb);
  auto e = ca::evaluate(via_lcms, test.lab);
  std::cout << "LUT profile (33^3 from rootpoly:3) on CC24: dE00 mean " << e.s00.mean << " max " << e.s00.max
            << "; max dE00 vs the model itself " << max_de00(direct, via_lcms) << "\n";
  // Interpolating a 33³ table of a smooth model: well under the model's own error.
  EXPECT_LT(max_de00(direct, via_lcms), 0.1);
  EXPECT_LT(e.s00.mean, 0.75);
  if (!ca::testing::have_tool("xicclu")) GTEST_SKIP() << "xicclu not installed (argyll): Argyll cross-check skipped";
  auto dir = ca::testing::temp_dir("icc-lut");
  profile.save(dir / "lut.icc");
  Eigen::MatrixXd argyll = xicclu(dir / "lut.icc", test.rgb, dir);
  ASSERT_EQ(argyll.rows(), test.rgb.rows()) << "xicclu could not read the profile";
  EXPECT_LT(max_de00(argyll, via_lcms), 0.1);
}

TEST(AnalysisIccProfile, BadInputs) {
  ca::IccProfile junk{{1, 2, 3, 4}};
  EXPECT_THROW(ca::apply_profile(junk, Eigen::MatrixXd::Ones(1, 3)), colorlab::Error);
  ca::ChartData c;
  EXPECT_THROW(ca::build_matrix_shaper_profile(c), colorlab::Error);
}

}  // namespace
