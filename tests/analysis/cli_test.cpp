// `colorlab analyze ...` end to end on files: parses real command lines and checks the printed numbers against the
// library (and, for de2000, against Sharma's published values).
#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "colorlab/analysis/blackbox.hpp"
#include "colorlab/analysis/chart_io.hpp"
#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/cli/analyze_command.hpp"
#include "colorlab/core/error.hpp"
#include "test_support.hpp"

namespace ca = colorlab::analysis;

namespace {

std::string run_cli(std::vector<std::string> args) {
  CLI::App app{"colorlab"};
  colorlab::cli::add_analyze_command(app);
  args.insert(args.begin(), "colorlab");
  std::vector<const char*> argv;
  for (auto& a : args) argv.push_back(a.c_str());
  ::testing::internal::CaptureStdout();
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (...) {
    ::testing::internal::GetCapturedStdout();
    throw;
  }
  return ::testing::internal::GetCapturedStdout();
}

TEST(AnalysisCli, XyzAndLabOfSpectra) {
  auto dir = ca::testing::temp_dir("cli");
  std::ofstream(dir / "s.csv") << "wavelength_nm,white,grey\n380,1,0.2\n500,1,0.2\n600,1,0.2\n730,1,0.2\n";
  std::string out = run_cli({"analyze", "lab", (dir / "s.csv").string(), "--illuminant", "D65"});
  EXPECT_NE(out.find("white,100,0,0"), std::string::npos) << out;
  EXPECT_NE(out.find("grey,51.8372,0,0"), std::string::npos) << out;  // 116·0.2^(1/3) − 16
  out = run_cli({"analyze", "xyz", (dir / "s.csv").string(), "--illuminant", "F11", "--observer", "10", "--json"});
  EXPECT_NE(out.find("\"xyz\""), std::string::npos) << out;
  EXPECT_NE(out.find("\"id\": \"grey\""), std::string::npos) << out;
  EXPECT_THROW(run_cli({"analyze", "xyz", (dir / "s.csv").string(), "--observer", "4"}), CLI::ValidationError);
}

TEST(AnalysisCli, De2000OnSharmaPairs) {
  COLORLAB_REQUIRE_SHARED(pairs, "ciede2000_sharma2005_34pairs.csv");
  std::string out = run_cli({"analyze", "de2000", pairs.string()});
  EXPECT_NE(out.find("\n1,2.04246,"), std::string::npos) << out;  // pair 1: Sharma 2.0425
  EXPECT_NE(out.find("dE00,"), std::string::npos);
}

TEST(AnalysisCli, FitWithCrossValidationAndTestChart) {
  COLORLAB_REQUIRE_SHARED(sg, "testvec_sg140_canon20d_d50_argyll.csv");
  COLORLAB_REQUIRE_SHARED(cc, "testvec_cc24_canon20d_d50_argyll.csv");
  std::string out = run_cli({"analyze", "fit", "--method", "rootpoly:2", "--train", sg.string(), "--test", cc.string(), "--cv", "k5"});
  EXPECT_NE(out.find("rootpoly:2,6,xyz"), std::string::npos) << out;
  EXPECT_NE(out.find("# test_summary"), std::string::npos) << out;
  out = run_cli({"analyze", "fit", "--train", sg.string(), "--json"});
  EXPECT_NE(out.find("\"model\""), std::string::npos);
  EXPECT_NE(out.find("\"rbf:ccm\""), std::string::npos) << "auto must try the spline family too";
  out = run_cli({"analyze", "fit", "--method", "rbf:ccm", "--train", sg.string(), "--cv", "loo"});
  EXPECT_NE(out.find("\nrbf:ccm,7,xyz,"), std::string::npos) << out;
  EXPECT_THROW(run_cli({"analyze", "fit", "--method", "poly:12", "--train", sg.string()}), colorlab::Error);
}

// --basis: the CLI's curves equal the library's prior fit on the same inputs, and (noise-free RAW from the Canon 20D,
// the 20D left out of the basis) lie within 10 % of peak of the truth.
TEST(AnalysisCli, BlackBoxWithBasisOfOtherCameras) {
  COLORLAB_REQUIRE_SHARED(ssf_file, "camera_ssf_canon_eos_20d_camspec_10nm_400_720.csv");
  COLORLAB_REQUIRE_SHARED(cams_file, "camera_ssf_camspec_jiang2013_28cams_10nm_400_720.csv");
  COLORLAB_REQUIRE_SHARED(sg_file, "colorcheckersg_xrite_before_nov2014_dcamprof_10nm_380_730.csv");
  ca::SpectralSet ssf = ca::read_spectra(ssf_file);
  ca::SpectralSet sg = ca::read_spectra(sg_file);  // 380–730 nm: the CLI crops to the basis's 400–720 nm
  ca::SpectralSet refl = ca::resample(sg, ssf.wavelengths, ca::Interpolation::linear);
  ca::SpectralSet lamp = ca::resample(ca::load_illuminant("D65"), ssf.wavelengths, ca::Interpolation::linear);
  Eigen::MatrixXd spectra = refl.values.array().rowwise() * lamp.values.row(0).array();
  Eigen::MatrixXd raw = spectra * ssf.values.transpose();
  const double gain = 4095 * 0.9 / raw.maxCoeff();
  raw *= gain;
  auto dir = ca::testing::temp_dir("cli-blackbox");
  {
    std::ofstream f(dir / "raw.csv");
    f.precision(17);
    f << "patch,R,G,B\n";
    for (Eigen::Index i = 0; i < raw.rows(); ++i)
      f << sg.names[static_cast<std::size_t>(i)] << ',' << raw(i, 0) << ',' << raw(i, 1) << ',' << raw(i, 2) << '\n';
  }
  const std::string out = run_cli({"analyze", "fit", "--method", "blackbox", "--train", (dir / "raw.csv").string(), "--spectra",
                                   sg_file.string(), "--illuminant", "D65", "--basis", cams_file.string(), "--exclude-camera",
                                   "Canon_20D", "--json"});
  const auto j = nlohmann::json::parse(out);
  const auto& rows = j.at("sensitivities");
  ASSERT_EQ(rows.size(), ssf.wavelengths.size());
  ca::BlackBoxOptions o;
  o.prior = ca::learn_sensitivity_prior(ca::read_spectra(cams_file), ssf.wavelengths, {"Canon_20D"});
  const auto lib = ca::fit_blackbox(spectra, raw, o);
  for (int c = 0; c < 3; ++c) {
    const double peak = gain * ssf.values.row(c).maxCoeff();
    double worst = 0;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const double v = rows[k].at(std::string(1, "RGB"[c])).get<double>();
      EXPECT_NEAR(v, lib.sensitivities(c, static_cast<Eigen::Index>(k)), 1e-6 * peak);
      worst = std::max(worst, std::abs(v - gain * ssf.values(c, static_cast<Eigen::Index>(k))) / peak);
    }
    EXPECT_LE(worst, 0.10) << "RGB"[c];
  }
  EXPECT_THROW(run_cli({"analyze", "fit", "--method", "blackbox", "--train", (dir / "raw.csv").string(), "--spectra",
                        sg_file.string(), "--exclude-camera", "Canon_20D"}),
               colorlab::Error);
}

TEST(AnalysisCli, UniformityAndAveraging) {
  auto dir = ca::testing::temp_dir("cli2");
  {
    std::ofstream g(dir / "grid.csv");
    for (int r = 0; r < 8; ++r) {
      for (int c = 0; c < 10; ++c) g << (c ? "," : "") << 200 + r * 3 + c * 5;
      g << "\n";
    }
  }
  std::string out = run_cli({"analyze", "uniformity", (dir / "grid.csv").string()});
  EXPECT_NE(out.find("# placement"), std::string::npos) << out;
  EXPECT_NE(out.find("200,266,66"), std::string::npos) << out;  // min, max, range
  // Two 16-bit 4×2 PGM frames.
  for (int f = 0; f < 2; ++f) {
    std::ofstream p(dir / ("f" + std::to_string(f) + ".pgm"), std::ios::binary);
    p << "P5\n4 2\n65535\n";
    for (int i = 0; i < 8; ++i) {
      int v = 1000 + 10 * f;
      p.put(static_cast<char>(v >> 8)).put(static_cast<char>(v & 255));
    }
  }
  out = run_cli({"analyze", "averaging", (dir / "f0.pgm").string(), (dir / "f1.pgm").string()});
  EXPECT_NE(out.find("stdev over 2 frames,7.07107,7.07107"), std::string::npos) << out;
}

}  // namespace
