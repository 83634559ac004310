// lab.analysis.characterize's black box (§7.4) in process, on a synthetic photograph whose truth is
// known: the simulated lab's SG reflectances under CIE F11 (the TL84 tube: its mercury lines test
// how the lamp's 5 nm table is carried onto the chart's 10 nm bands), a camera with smooth
// Gaussian-lobed curves integrated on the lamp's own 5 nm grid, 0.5 % multiplicative noise on the
// counts. The bounds come from that noise and from the dissertation's Table 13, not from a run.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "colorlab/analysis/characterization.hpp"
#include "colorlab/analysis/color_difference.hpp"
#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/campaigns/characterize.hpp"
#include "colorlab/campaigns/characterize_lamps.hpp"
#include "colorlab/core/data_paths.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/sim/scene.hpp"

using namespace colorlab;
using nlohmann::json;

namespace {

constexpr double kNoise = 0.005;  // relative σ of a patch's counts
constexpr double kFullScale = 4095;

// Smooth silicon-behind-dyes curves with secondary lobes (as the simulator's parametric camera).
double sensitivity(int channel, double nm) {
  struct Lobe {
    double centre, width, weight;
  };
  static const Lobe lobes[3][2] = {{{600, 38, 1.0}, {450, 25, 0.04}}, {{535, 42, 1.0}, {610, 30, 0.08}}, {{460, 30, 1.0}, {530, 30, 0.10}}};
  double v = 0;
  for (const auto& l : lobes[channel]) v += l.weight * std::exp(-0.5 * std::pow((nm - l.centre) / l.width, 2));
  return v * (nm > 680 ? std::exp(-(nm - 680) / 15.0) : 1.0);
}

struct Synthetic {
  json camera, reference;
  Eigen::MatrixXd truth;      // n × 3 noiseless counts
  analysis::ChartData chart;  // noisy counts with the reference colours
};

Synthetic make_chart(std::uint64_t seed) {
  auto clock = std::make_shared<sim::SimClock>(1.0);
  sim::Scene scene(sim::SceneConfig{}, clock);
  const auto& patches = scene.chart().patches;
  const auto lamp = analysis::load_illuminant("F11");  // colord: 5 nm
  const auto d50 = analysis::load_illuminant("D50");
  const auto observer = analysis::load_observer(analysis::Observer::cie1931_2deg);
  const auto grid = analysis::uniform_grid(380, 730, 10);
  analysis::ReflectanceIntegrator integrator(d50, observer, grid);
  Synthetic s;
  const auto n = static_cast<Eigen::Index>(patches.size());
  s.truth.resize(n, 3);
  json ids = json::array(), lab = json::array(), xyz = json::array(), spectra = json::array();
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& r = patches[static_cast<std::size_t>(i)].reflectance;
    for (int c = 0; c < 3; ++c) {
      double sum = 0;
      for (std::size_t k = 0; k < lamp.bands(); ++k) {
        const double nm = lamp.wavelengths[k];
        if (nm < 380 || nm > 730) continue;
        sum += sensitivity(c, nm) * lamp.values(0, static_cast<Eigen::Index>(k)) * r.at(nm);
      }
      s.truth(i, c) = sum;
    }
    Eigen::RowVectorXd refl(static_cast<Eigen::Index>(grid.size()));
    for (std::size_t k = 0; k < grid.size(); ++k) refl(static_cast<Eigen::Index>(k)) = r.at(grid[k]);
    const auto x = integrator.xyz(refl);
    const auto l = analysis::xyz_to_lab(x, analysis::kIccD50White);
    ids.push_back(patches[static_cast<std::size_t>(i)].name);
    xyz.push_back({x.X, x.Y, x.Z});
    lab.push_back({l.L, l.a, l.b});
    spectra.push_back(std::vector<double>(refl.data(), refl.data() + refl.size()));
  }
  s.truth *= 0.9 * kFullScale / s.truth.maxCoeff();  // the brightest patch at 90 % of a 12-bit raw
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0, 1);
  json values = json::array();
  s.chart.rgb.resize(n, 3);
  s.chart.xyz.resize(n, 3);
  s.chart.lab.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    json v = json::array();
    for (int c = 0; c < 3; ++c) {
      s.chart.rgb(i, c) = s.truth(i, c) * (1 + kNoise * unit(rng));
      s.chart.xyz(i, c) = xyz[static_cast<std::size_t>(i)][static_cast<std::size_t>(c)];
      s.chart.lab(i, c) = lab[static_cast<std::size_t>(i)][static_cast<std::size_t>(c)];
      v.push_back(s.chart.rgb(i, c));
    }
    values.push_back(v);
    s.chart.ids.push_back(ids[static_cast<std::size_t>(i)]);
  }
  s.camera = {{"format", "raw"}, {"bits", 12}, {"ids", ids}, {"values", values}};
  s.reference = {{"ids", ids}, {"Lab", lab}, {"XYZ", xyz}, {"wavelengths", grid}, {"spectra", spectra}};
  return s;
}

TEST(CharacterizeBlackBox, PredictsHeldOutPatchesWithinTheInjectedNoise) {
  const Synthetic s = make_chart(7);
  const json c = campaigns::characterize(s.camera, s.reference, {{"lamp", "TL84"}});
  ASSERT_TRUE(c["approaches"].contains("black_box")) << c["not_fitted"].dump();
  const json& b = c["approaches"]["black_box"];
  EXPECT_EQ(b["illuminant"], "F11");
  EXPECT_NE(b["spd"].get<std::string>().find("CIE-F11"), std::string::npos) << b["spd"];
  EXPECT_EQ(b["mapping"]["method"], c["selected"]["method"]);
  // An honest error is never below the fit's own.
  EXPECT_GE(b["cv"]["mean"].get<double>(), b["training"]["mean"].get<double>());

  // Counts: a held-out patch's predicted counts are as close to the photograph's as the noise lets
  // two photographs be: E|x₁ − x₂| = 2σ/√π for σ = 0.5 % of the value. The dissertation's own
  // figure (Table 13, training, Canon 20D) is a mean of 1.29–1.60 % of full scale.
  const double dissertation_mean_pct[3] = {1.60, 1.56, 1.29};
  for (int c3 = 0; c3 < 3; ++c3) {
    const std::string ch(1, "RGB"[c3]);
    const double two_photos = 2 * kNoise * s.truth.col(c3).mean() / std::sqrt(M_PI);
    const json& r = b["residuals"]["cv"][ch];
    std::cout << "[black box] " << ch << ": cv mean " << r["mean"] << " counts (" << r["mean_pct"] << " % FS), max "
              << r["max"] << "; two photographs differ by " << two_photos << " on average\n";
    EXPECT_LE(r["mean"].get<double>(), two_photos) << ch;
    EXPECT_LE(r["mean_pct"].get<double>(), dissertation_mean_pct[c3]) << ch;
    // The stored per-patch residuals are the table's: |r| over the patches gives its min, mean and max.
    for (const char* set : {"training", "cv"}) {
      const json& patches = b["residuals"]["patches"][set];
      const json& stats = b["residuals"][set][ch];
      ASSERT_EQ(patches["ids"].size(), patches[ch].size());
      ASSERT_EQ(patches["ids"].size(), static_cast<std::size_t>(s.truth.rows()));
      double lo = INFINITY, hi = 0, sum = 0;
      for (const auto& v : patches[ch]) {
        lo = std::min(lo, std::abs(v.get<double>()));
        hi = std::max(hi, std::abs(v.get<double>()));
        sum += std::abs(v.get<double>());
      }
      EXPECT_DOUBLE_EQ(stats["min"].get<double>(), lo) << set << " " << ch;
      EXPECT_DOUBLE_EQ(stats["max"].get<double>(), hi) << set << " " << ch;
      EXPECT_NEAR(stats["mean"].get<double>(), sum / static_cast<double>(patches[ch].size()), 1e-9 * hi) << set << " " << ch;
      EXPECT_LE(stats["min"].get<double>(), stats["mean"].get<double>());
    }
  }

  // ΔE00: the black box's held-out L*a*b* against what the same mapping, refitted without the
  // patch, makes of a second photograph of it (the truth with fresh noise): predicting the counts
  // from the spectrum must do at least as well as photographing the patch again.
  analysis::FitOptions fo;
  for (auto t : {analysis::FitTarget::xyz_then_lab, analysis::FitTarget::lab_direct, analysis::FitTarget::xyz_lightness_weighted}) {
    if (c["selected"]["target"] == analysis::to_string(t)) fo.target = t;
  }
  const std::string method = c["selected"]["method"];
  std::mt19937_64 rng(99);
  std::normal_distribution<double> unit(0, 1);
  double second_photo = 0;
  for (std::size_t i = 0; i < s.chart.size(); ++i) {
    std::vector<std::size_t> keep;
    for (std::size_t j = 0; j < s.chart.size(); ++j) {
      if (j != i) keep.push_back(j);
    }
    Eigen::MatrixXd again(1, 3);
    for (int c3 = 0; c3 < 3; ++c3) again(0, c3) = s.truth(static_cast<Eigen::Index>(i), c3) * (1 + kNoise * unit(rng));
    const Eigen::MatrixXd lab = analysis::fit_method(method, s.chart.subset(keep), fo).apply(again);
    const auto ref = s.chart.lab.row(static_cast<Eigen::Index>(i));
    second_photo += analysis::delta_e2000({lab(0, 0), lab(0, 1), lab(0, 2)}, {ref(0), ref(1), ref(2)});
  }
  second_photo /= static_cast<double>(s.chart.size());
  std::cout << "[black box] " << method << ": cv mean ΔE00 " << b["cv"]["mean"] << " (training " << b["training"]["mean"]
            << "); the mapping on a second photograph " << second_photo << "; " << b["regularisation"]["kind"] << "\n";
  EXPECT_LE(b["cv"]["mean"].get<double>(), second_photo);

  // With the shared data set the curves carry their 95 % credible band.
  if (b["regularisation"]["kind"].get<std::string>().rfind("prior", 0) == 0) {
    EXPECT_EQ(b["sensitivities"]["B_low"].size(), b["sensitivities"]["wavelengths"].size());
  }
}

TEST(CharacterizeBlackBox, SaysWhyItWasNotFitted) {
  const Synthetic s = make_chart(3);
  // A cabinet left as it is: no known spectrum for the light.
  json c = campaigns::characterize(s.camera, s.reference, {{"lamp", ""}, {"cv", "k5"}});
  EXPECT_FALSE(c["approaches"].contains("black_box"));
  EXPECT_NE(c["not_fitted"]["black_box"].get<std::string>().find("lamp"), std::string::npos) << c["not_fitted"];
  // A reference without spectra (a chart-read stored before them).
  json no_spectra = s.reference;
  no_spectra.erase("spectra");
  c = campaigns::characterize(s.camera, no_spectra, {{"lamp", "D65"}, {"cv", "k5"}});
  EXPECT_NE(c["not_fitted"]["black_box"].get<std::string>().find("spectra"), std::string::npos) << c["not_fitted"];
  // Processed formats are not linear: no black box, nothing said.
  json tiff = s.camera;
  tiff["format"] = "tiff16";
  tiff["bits"] = 16;
  c = campaigns::characterize(tiff, s.reference, {{"lamp", "D65"}, {"cv", "k5"}});
  EXPECT_FALSE(c["approaches"].contains("black_box"));
  EXPECT_FALSE(c["not_fitted"].contains("black_box"));
  // characterize_black_box refuses rather than returns nothing.
  EXPECT_THROW(campaigns::characterize_black_box(s.camera, s.reference, {{"lamp", "UV"}, {"mapping", {{"method", "ccm"}, {"target", "xyz"}}}}),
               Error);
}

// Issue 26: one characterization per other lamp, named by it, from the raw's sensitivities; a lamp known only by its
// standard's name is warned about, a measured one is not. (Accuracy against truth: tests/analysis/across_lamps_test.)
TEST(CharacterizeAcrossLamps, OnePerOtherLampNamedByItAndNominalLampsWarned) {
  if (!paths::shared_data_file("camera_ssf_camspec_jiang2013_28cams_10nm_400_720.csv")) GTEST_SKIP() << "no camspec curves (../shared/data)";
  const Synthetic s = make_chart(5);
  const auto a = analysis::load_illuminant("A");
  json measured_a{{"wavelengths", a.wavelengths}, {"values", std::vector<double>(a.values.data(), a.values.data() + a.values.size())}};
  const json options{{"lamp", "TL84"}, {"target_lamps", {"TL84", "A", "CWF"}}, {"draws", 5}, {"lamp_spectra", {{"A", measured_a}}}};
  const json out = campaigns::characterize_across_lamps(s.chart, s.reference, options);
  EXPECT_FALSE(out.contains("TL84")) << "the photographed lamp is the adapted mapping's, not an across-lamps one";
  ASSERT_TRUE(out.contains("A"));
  ASSERT_TRUE(out.contains("CWF"));
  EXPECT_TRUE(out["A"]["lamp_measured"].get<bool>());
  EXPECT_TRUE(out["A"]["warnings"].empty());
  EXPECT_FALSE(out["CWF"]["lamp_measured"].get<bool>());
  ASSERT_EQ(out["CWF"]["warnings"].size(), 1u);
  EXPECT_NE(out["CWF"]["warnings"][0].get<std::string>().find("nominal"), std::string::npos);
  EXPECT_EQ(out["CWF"]["method"].get<std::string>().rfind("across-lamps:CWF:", 0), 0u) << out["CWF"]["method"];
  EXPECT_EQ(out["A"]["uncertainty95"]["de00"].size(), s.chart.size());
  for (const auto& r : out["A"]["uncertainty95"]["de00"]) EXPECT_GT(r.get<double>(), 0);

  json no_spectra = s.reference;
  no_spectra.erase("spectra");
  EXPECT_THROW((void)campaigns::characterize_across_lamps(s.chart, no_spectra, options), Error);
  EXPECT_THROW((void)campaigns::characterize_across_lamps(s.chart, s.reference, {{"lamp", "TL84"}, {"target_lamps", {"sodium"}}}), Error);
}

}  // namespace
