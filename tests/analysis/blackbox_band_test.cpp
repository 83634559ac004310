// Issue 12, black box: a credible band for every recovered sensitivity curve, and how often the truth lies inside it —
// on every camera of the camspec collection left out of the prior in turn, and on cameras the prior never saw
// (the rawtoaces/NPL measurements of other bodies). Synthesis as in characterization_test: SG reflectances × D65,
// brightest patch at 90 % of 4095, 0.5 % multiplicative Gaussian RAW noise, 400–720 nm at 10 nm.
#include <gtest/gtest.h>

#include <algorithm>
#include <iomanip>
#include <random>

#include "colorlab/analysis/blackbox.hpp"
#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/analysis/statistics.hpp"
#include "test_support.hpp"

namespace ca = colorlab::analysis;

namespace {

constexpr double kZ = 1.96;     // pointwise 95 % band of the posterior
constexpr int kDraws = 10;      // noise draws per camera (seeds 0–9)
constexpr double kRate = 0.90;  // issue 12's stated rate: the truth inside the band at ≥ 90 % of wavelengths

struct Coverage {
  long inside = 0, bands = 0, curves = 0, curves_at_rate = 0;
  long misses = 0, misses_inside = 0;  // band values where the point estimate is off by > 10 % of peak
  double worst = 1;
  std::string worst_where;
  std::vector<double> curve_error;  // max |error| / peak per curve
  void add(double fraction, long in, long n, const std::string& where) {
    inside += in;
    bands += n;
    ++curves;
    curves_at_rate += fraction >= kRate;
    if (fraction < worst) {
      worst = fraction;
      worst_where = where;
    }
  }
  double pooled() const { return static_cast<double>(inside) / static_cast<double>(bands); }
};

// Fits every draw of one camera and scores its bands against the truth.
void score_camera(const Eigen::MatrixXd& spectra, Eigen::MatrixXd truth, const ca::SensitivityPrior& prior,
                  const std::string& name, Coverage& cov) {
  Eigen::MatrixXd clean = spectra * truth.transpose();
  const double gain = 4095 * 0.9 / clean.maxCoeff();
  clean *= gain;
  truth *= gain;
  ca::BlackBoxOptions o;
  o.prior = prior;
  for (int seed = 0; seed < kDraws; ++seed) {
    std::mt19937 rng(static_cast<unsigned>(seed));
    std::normal_distribution<double> nd(0, 1);
    Eigen::MatrixXd raw = clean;
    for (Eigen::Index i = 0; i < raw.rows(); ++i)
      for (int c = 0; c < 3; ++c) raw(i, c) *= 1 + 0.005 * nd(rng);
    const auto m = ca::fit_blackbox(spectra, raw, o);
    ASSERT_EQ(m.sensitivity_sdev.rows(), 3);
    for (int c = 0; c < 3; ++c) {
      const auto band = ca::credible_band(m.sensitivities.row(c).transpose(), m.sensitivity_sdev.row(c).transpose(), kZ);
      long in = 0;
      const double peak = truth.row(c).maxCoeff();
      for (Eigen::Index k = 0; k < band.lower.size(); ++k) {
        const bool inside = truth(c, k) >= band.lower(k) && truth(c, k) <= band.upper(k);
        in += inside;
        if (std::abs(m.sensitivities(c, k) - truth(c, k)) > 0.10 * peak) {
          ++cov.misses;
          cov.misses_inside += inside;
        }
      }
      cov.add(static_cast<double>(in) / static_cast<double>(band.lower.size()), in, band.lower.size(),
              name + " " + "RGB"[c] + " seed " + std::to_string(seed));
      cov.curve_error.push_back((m.sensitivities.row(c) - truth.row(c)).cwiseAbs().maxCoeff() / truth.row(c).maxCoeff());
    }
  }
}

void report(const char* what, const Coverage& cov) {
  const auto e = ca::summarize(cov.curve_error);
  const auto within = std::count_if(cov.curve_error.begin(), cov.curve_error.end(), [](double x) { return x <= 0.10; });
  std::cout << std::fixed << std::setprecision(1) << what << ": truth inside the 95 % band at " << 100 * cov.pooled()
            << " % of all " << cov.bands << " band values; " << cov.curves_at_rate << "/" << cov.curves << " curves ("
            << 100.0 * cov.curves_at_rate / cov.curves << " %) at >= 90 % of their wavelengths; worst curve " << 100 * cov.worst
            << " % (" << cov.worst_where << "); point-estimate error median " << 100 * e.median << " %, max " << 100 * e.max
            << " % of peak, within 10 % of peak in " << within << "/" << cov.curve_error.size() << " curves; where it misses 10 %, the band holds the truth at " << cov.misses_inside << "/" << cov.misses << " band values\n";
}

class AnalysisBlackBoxBand : public ::testing::Test {
 protected:
  void SetUp() override {
    auto cams = ca::testing::shared("camera_ssf_camspec_jiang2013_28cams_10nm_400_720.csv");
    auto sg = ca::testing::shared("colorcheckersg_xrite_before_nov2014_dcamprof_10nm_380_730.csv");
    if (!cams || !sg) GTEST_SKIP() << "camspec curves or SG spectra not present (../shared/data)";
    cams_ = ca::read_spectra(*cams);
    const auto refl = ca::resample(ca::read_spectra(*sg), cams_.wavelengths, ca::Interpolation::linear);
    const auto lamp = ca::resample(ca::load_illuminant("D65"), cams_.wavelengths, ca::Interpolation::linear);
    spectra_ = refl.values.array().rowwise() * lamp.values.row(0).array();
  }
  Eigen::MatrixXd truth_of(const ca::SpectralSet& set, const std::string& camera) const {
    const auto on_grid = ca::resample(set, cams_.wavelengths, ca::Interpolation::linear);
    Eigen::MatrixXd t(3, static_cast<Eigen::Index>(cams_.wavelengths.size()));
    for (int c = 0; c < 3; ++c) t.row(c) = on_grid.values.row(static_cast<Eigen::Index>(on_grid.require(camera + "_" + "RGB"[c])));
    return t;
  }
  ca::SpectralSet cams_;
  Eigen::MatrixXd spectra_;
};

// Goal (issue 12): on every draw and every camera left out, the truth inside its band at ≥ 90 % of wavelengths.
// NOT MET per curve: 689 of the 840 curves (82 %) reach it. The misses are cameras unlike the other 27 (worst: Canon
// 60D blue on seed 8, 36 %, where the restricted likelihood puts its weight on a heavy prior weight): a prior learned
// from 27 cameras cannot know how a 28th departs from them. Where the point estimate misses 10 % of peak, the band
// holds the truth at only 237 of 559 such values. What the band does achieve, and what is asserted: it is calibrated
// — pooled over all cameras, draws and wavelengths the truth lies inside at ≥ 90 % (measured 94.0 % for a nominal
// 95 %); the point estimate alone is within 10 % of peak in 575 of 840 curves. Before the λ mixture and the
// out-of-span variance (sensitivity_prior.cpp) the same band covered 88 % pooled, worst curve 9 %.
TEST_F(AnalysisBlackBoxBand, EveryCamspecCameraLeftOutInTurnIsCoveredAtTheStatedRatePooled) {
  Coverage cov;
  for (const auto& cam : ca::camera_names(cams_)) {
    const auto prior = ca::learn_sensitivity_prior(cams_, cams_.wavelengths, {cam});
    ASSERT_EQ(prior.cameras.size(), 27u);
    score_camera(spectra_, truth_of(cams_, cam), prior, cam, cov);
  }
  report("camspec, each camera left out", cov);
  EXPECT_EQ(cov.curves, 28 * kDraws * 3);
  EXPECT_GE(cov.pooled(), kRate);
}

// The same on cameras outside the collection the prior is learned from (all 28 camspec cameras go into it): an
// independent check that the calibration above was not a property of the camspec set itself. Measured: 94.4 % pooled;
// 174 of 210 curves at ≥ 90 % of their wavelengths (the per-curve goal is not met here either; worst 58 %, the
// PowerShot S90's blue).
TEST_F(AnalysisBlackBoxBand, CamerasTheCollectionNeverSawAreCoveredAtTheStatedRatePooled) {
  auto file = ca::testing::shared("camera_ssf_rawtoaces_11cams_5nm_380_780.csv");
  if (!file) GTEST_SKIP() << "rawtoaces camera curves not present (../shared/data)";
  const auto others = ca::read_spectra(*file);
  const auto prior = ca::learn_sensitivity_prior(cams_, cams_.wavelengths);
  Coverage cov;
  // The rawtoaces bodies that camspec does not also hold (it holds the 5D Mark II, D200, D5100 and D700).
  for (const char* cam : {"arri_d21", "canon_powershot_s90", "canon_xti", "nikon_d70", "nikon_d7000", "sony_ilce_7rm2", "sony_ilce_7sm2"})
    score_camera(spectra_, truth_of(others, cam), prior, cam, cov);
  report("rawtoaces cameras, prior from all 28 camspec", cov);
  EXPECT_GE(cov.pooled(), kRate);
}

}  // namespace
