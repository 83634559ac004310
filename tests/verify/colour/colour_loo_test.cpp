// The colour reader's parts that need no daemon (issue 23): the spline's one-solve leave-one-out against refitting
// without each patch (the definition of LOO), what it costs, and the refusals of runs that lack what colour needs.
#include <chrono>
#include <cmath>
#include <iostream>
#include <random>

#include <gtest/gtest.h>

#include "colorlab/analysis/characterization.hpp"
#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/scattered_data.hpp"
#include "colorlab/core/error.hpp"
#include "colour_from_runs.hpp"

using namespace colorlab;
using nlohmann::json;

namespace {

// 80 patches (the refits below cost n³ each): a camera that is a 3 × 3 of XYZ with a mild non-linearity and 0.5 % noise, so the spline has work.
analysis::ChartData chart(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.03, 0.9);
  std::normal_distribution<double> n(0, 0.005);
  analysis::ChartData d;
  d.white = {95.047, 100, 108.883};
  const Eigen::Index count = 80;
  d.rgb.resize(count, 3);
  d.xyz.resize(count, 3);
  d.lab.resize(count, 3);
  Eigen::Matrix3d m;
  m << 0.9, 0.3, 0.05, 0.2, 1.0, 0.1, 0.02, 0.15, 1.1;
  for (Eigen::Index i = 0; i < count; ++i) {
    const Eigen::Vector3d xyz(u(rng) * 95, u(rng) * 100, u(rng) * 108);
    Eigen::Vector3d cam = m * xyz;
    for (int c = 0; c < 3; ++c) cam[c] = 40 * std::pow(cam[c], 1.03) * (1 + n(rng));
    d.ids.push_back("P" + std::to_string(i));
    d.rgb.row(i) = cam.transpose();
    d.xyz.row(i) = xyz.transpose();
    const auto lab = analysis::xyz_to_lab({xyz[0], xyz[1], xyz[2]}, d.white);
    d.lab.row(i) << lab.L, lab.a, lab.b;
  }
  return d;
}

}  // namespace

TEST(VerifyColourLoo, SplineOneSolveEqualsRefittingWithoutEachPatch) {
  const analysis::ChartData d = chart(3);
  for (auto target : {analysis::FitTarget::xyz_then_lab, analysis::FitTarget::xyz_lightness_weighted, analysis::FitTarget::lab_direct}) {
    analysis::FitOptions fo;
    fo.target = target;
    analysis::SplineOptions so = analysis::spline_options("rbf:ccm", fo);
    so.smoothing = 1e-3;                // a fixed λ, as the verification takes the one chosen on every patch
    so.input_scale = d.rgb.maxCoeff();  // LOO of the same smoother: the scale is not refitted per fold
    const auto t0 = std::chrono::steady_clock::now();
    const Eigen::MatrixXd fast = analysis::spline_loo_targets(d, so);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    double worst = 0;
    for (std::size_t i = 0; i < d.size(); ++i) {
      std::vector<std::size_t> keep;
      for (std::size_t j = 0; j < d.size(); ++j)
        if (j != i) keep.push_back(j);
      const Eigen::MatrixXd held = analysis::fit_spline(d.subset(keep), so).predict_target(d.rgb.row(static_cast<Eigen::Index>(i)));
      for (int c = 0; c < 3; ++c) {
        const double ref = held(0, c);
        worst = std::max(worst, std::abs(fast(static_cast<Eigen::Index>(i), c) - ref) / std::max(1.0, std::abs(ref)));
      }
    }
    std::cout << analysis::to_string(target) << ": λ " << *so.smoothing << ", one-solve LOO of " << d.size() << " patches " << seconds * 1e3
              << " ms, largest relative difference from 140 refits " << worst << "\n";
    // Both are the same arithmetic up to rounding in a 144-unknown solve.
    EXPECT_LT(worst, 1e-6) << analysis::to_string(target);
  }
}

TEST(VerifyColourLoo, LampsHaveTheirStandardIlluminants) {
  EXPECT_EQ(verify::illuminant_of_lamp("D65"), "D65");
  EXPECT_EQ(verify::illuminant_of_lamp("TL84"), "F11");
  EXPECT_EQ(verify::illuminant_of_lamp("CWF"), "F2");
  EXPECT_EQ(verify::illuminant_of_lamp("A"), "A");
  try {
    verify::illuminant_of_lamp("UV");
    ADD_FAILURE() << "UV has no standard spectrum";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
    EXPECT_NE(std::string(e.what()).find("UV"), std::string::npos);
  }
}

namespace {

ErrorClass refusal(const std::vector<json>& runs, std::string& message) {
  verify::Rendering r;
  r.width = r.height = 4;
  r.pixels.assign(4 * 4 * 3, 1.0f);
  try {
    verify::measured_scene_from_runs(runs, r);
  } catch (const Error& e) {
    message = e.what();
    return e.cls();
  }
  message = "no error";
  return ErrorClass::internal;
}

json run(const std::string& id, const std::string& campaign, json params = json::object(), json summary = json::object()) {
  return {{"id", id}, {"campaign", campaign}, {"params", params}, {"summary", summary}, {"measurements", json::array()}};
}

}  // namespace

TEST(VerifyColourLoo, RunsThatLackWhatColourNeedsAreRefusedWithTheirCause) {
  std::string m;
  EXPECT_EQ(refusal({run("c1", "chart-read")}, m), ErrorClass::bad_parameter);
  EXPECT_NE(m.find("without a characterize-camera run"), std::string::npos) << m;
  EXPECT_EQ(refusal({run("k1", "characterize-camera", {{"reference_run", "c1"}})}, m), ErrorClass::bad_parameter);
  EXPECT_NE(m.find("c1"), std::string::npos) << m;
  EXPECT_EQ(refusal({run("k1", "characterize-camera", {{"reference_run", "c1"}}), run("k2", "characterize-camera")}, m),
            ErrorClass::bad_parameter);
  EXPECT_NE(m.find("two characterize-camera"), std::string::npos) << m;
  EXPECT_EQ(refusal({}, m), ErrorClass::bad_parameter);
  // A characterization without a raw result (e.g. formats = tiff8 only): no linear counts to compare.
  const json no_raw = run("k1", "characterize-camera", {{"reference_run", "c1"}}, {{"script", {{"formats", {{"tiff8", json::object()}}}}}});
  EXPECT_THROW(verify::refit_characterization(no_raw, run("c1", "chart-read"), "D65"), Error);
  try {
    verify::stored_black_box(no_raw);
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("raw characterization"), std::string::npos) << e.what();
  }
  // A raw result whose black box was not fitted says why.
  const json no_bb = run("k1", "characterize-camera", {{"reference_run", "c1"}},
                         {{"script", {{"formats", {{"raw", {
                                                               {"approaches", json::object()},
                                                               {"not_fitted", {{"black_box", "the reference has no spectra"}}},
                                                           }}}}}}});
  try {
    verify::stored_black_box(no_bb);
    ADD_FAILURE() << "no black box";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::not_found);
    EXPECT_NE(std::string(e.what()).find("the reference has no spectra"), std::string::npos) << e.what();
  }
}
